import re

from django.conf import settings
from django.test import Client

from tests.segmentation.base import BaseTestCase


class StaticTestCase(BaseTestCase):
    def test_whitenoise_serves_static_files(self):
        r = Client().get("/static/admin/css/base.css")
        self.assertEqual(r.status_code, 200)

    def test_it_serves_the_built_front_ends_assets(self):
        index = settings.FRONTEND_DIST / "index.html"
        if not index.is_file():
            self.skipTest(f"front end not built ({index} missing); `make frontend` builds it")
        assets = re.findall(r'(?:src|href)="(/static/[^"]+)"', index.read_text())
        self.assertTrue(assets, "index.html references no /static/ assets")
        for url in assets:
            self.assertEqual(Client().get(url).status_code, 200, url)


class CsrfTestCase(BaseTestCase):
    def test_the_app_page_sets_the_csrf_cookie_the_front_end_sends_back(self):
        browser = Client(enforce_csrf_checks=True)
        browser.force_login(self.alice)
        self.assertEqual(browser.post("/api/projects/", {"name": "x"}).status_code, 403)

        browser.get("/")
        token = browser.cookies["csrftoken"].value
        r = browser.post("/api/projects/", {"name": "x"}, HTTP_X_CSRFTOKEN=token)
        self.assertEqual(r.status_code, 201)
