"""The pages under the service's Content-Security-Policy, the POST-only sign-out, and the
API docs served without a CDN, in a real browser."""

from playwright.sync_api import expect


def watch_csp(page):
    """Collect the console's reports of anything the policy blocked."""
    violations = []
    page.on("console", lambda msg: violations.append(msg.text)
            if "Content Security Policy" in msg.text else None)
    return violations


def test_it_signs_out_with_the_top_bar_button(live_server, new_page, studio):
    page = new_page("bob")
    expect(page.locator(".pager")).to_contain_text("capture")
    page.get_by_test_id("logout").click()
    page.wait_for_url(f"{live_server.url}/login/")
    page.goto(f"{live_server.url}/library/")
    page.wait_for_url(f"{live_server.url}/login/?next=/library/")


def test_the_pages_work_under_the_content_security_policy(live_server, new_page, ingested_capture, studio):
    page = new_page("alice")
    violations = watch_csp(page)
    expect(page.locator(".pager")).to_contain_text("1 capture")
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/")
    expect(page.get_by_test_id("capture-name")).to_have_text(ingested_capture.name)
    page.wait_for_selector("[data-testid=frames-loading][data-done]", state="attached")
    page.goto(f"{live_server.url}/library/")
    expect(page.get_by_test_id("nav-library")).to_be_visible()
    page.goto(f"{live_server.url}/projects/{studio['project'].pk}/dashboard/")
    expect(page.get_by_test_id("nav-dashboard")).to_be_visible()
    assert violations == [] and page.errors == [], (violations, page.errors)


def test_the_api_docs_render_offline_under_the_policy(live_server, new_page, studio):
    page = new_page("bob")
    violations = watch_csp(page)
    outside = []
    page.on("request", lambda request: outside.append(request.url)
            if not request.url.startswith(live_server.url) else None)
    page.goto(f"{live_server.url}/api/docs/")
    expect(page.locator(".swagger-ui .info .title")).to_contain_text("Cutroom API")
    expect(page.locator(".opblock-tag-section").first).to_be_visible()
    assert violations == [] and outside == [], (violations, outside)
