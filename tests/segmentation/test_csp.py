import re

from django.test import Client

from tests.segmentation.base import BaseTestCase


def policy(response):
    header = response["Content-Security-Policy"]
    return dict(part.strip().split(" ", 1) for part in header.split(";"))


class ContentSecurityPolicyTestCase(BaseTestCase):
    def test_the_login_page_allows_scripts_only_from_the_service(self):
        csp = policy(Client().get("/login/"))
        self.assertEqual(csp["script-src"], "'self'")
        self.assertEqual(csp["object-src"], "'none'")
        self.assertEqual(csp["frame-ancestors"], "'none'")
        self.assertEqual(csp["form-action"], "'self'")

    def test_the_app_page_and_the_api_docs_carry_the_policy(self):
        browser = Client()
        browser.force_login(self.bob)
        for path in ("/", "/api/docs/", "/admin/login/"):
            self.assertEqual(policy(browser.get(path))["default-src"], "'self'", path)


class ApiDocsTestCase(BaseTestCase):
    def test_the_api_docs_page_loads_only_local_assets(self):
        browser = Client()
        page = browser.get("/api/docs/").content.decode()
        assets = re.findall(r'<(?:script|link)\b[^>]*\b(?:src|href)="([^"]+)"', page)
        self.assertGreaterEqual(len(assets), 4, assets)  # css, favicon, bundle, preset, start-up
        for url in assets:
            self.assertTrue(url.startswith("/") and not url.startswith("//"), url)
            self.assertEqual(browser.get(url).status_code, 200, url)
        self.assertNotRegex(page, r"https?://")

    def test_the_api_docs_page_runs_no_inline_script(self):
        page = Client().get("/api/docs/").content.decode()
        scripts = re.findall(r"<script\b([^>]*)>(.*?)</script>", page, re.DOTALL)
        self.assertTrue(scripts)
        self.assertTrue(all("src=" in attrs and not body.strip() for attrs, body in scripts), scripts)
