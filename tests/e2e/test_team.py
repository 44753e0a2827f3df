"""The Team page in Chromium: an admin invites (and cancels), changes roles, removes, is
refused demoting the last admin, edits the label taxonomy; a site admin creates an
account with a one-time password; a reviewer sees the team but cannot change roles; an
annotator cannot open the page. With more than nine labels, the palette applies one."""

from playwright.sync_api import expect

from tests.e2e.test_queue import fetch


def test_an_admin_manages_the_team(live_server, new_page, studio, screenshots):
    from django.contrib.auth import get_user_model

    from segmentation.models import Invitation

    get_user_model().objects.create_user("dana", password="dana-password")
    project = studio["project"]
    alice = new_page("alice")
    alice.get_by_test_id("filter-project").select_option(str(project.pk))
    alice.get_by_test_id("nav-team").click()
    expect(alice.get_by_test_id("members").locator("tr")).to_have_count(4)

    alice.get_by_test_id("invite-form-username").fill("dana")
    alice.get_by_test_id("invite-form-role").select_option("reviewer")
    alice.get_by_test_id("invite-form").get_by_role("button", name="Invite").click()
    expect(alice.get_by_test_id("invitation-dana")).to_contain_text("dana as reviewer")
    assert project.role_of(get_user_model().objects.get(username="dana")) is None

    alice.get_by_test_id("role-bob").select_option("reviewer")
    expect(alice.locator(".toast", has_text="bob is now reviewer")).to_be_visible()
    assert project.role_of(studio["bob"]) == "reviewer"

    alice.get_by_test_id("role-alice").select_option("annotator")
    expect(alice.locator(".toast-error")).to_contain_text("last admin")
    expect(alice.get_by_test_id("role-alice")).to_have_value("admin")
    assert project.role_of(studio["alice"]) == "admin"
    alice.evaluate("document.querySelector('.toasts')?.replaceChildren()")  # a clean picture
    alice.screenshot(path=str(screenshots / "team.png"), full_page=True)

    alice.get_by_test_id("cancel-invitation-dana").click()
    expect(alice.get_by_test_id("pending-invitations")).to_have_text("No pending invitations.")
    assert Invitation.objects.get(username="dana").status == "cancelled"

    alice.get_by_test_id("remove-bob").click()
    alice.get_by_test_id("confirm-ok").click()
    expect(alice.get_by_test_id("member-bob")).to_have_count(0)
    assert project.role_of(studio["bob"]) is None
    assert alice.errors == []


def test_a_site_admin_creates_an_account_with_a_one_time_password(live_server, new_page, studio):
    from django.contrib.auth import get_user_model

    studio["alice"].is_superuser = True
    studio["alice"].save()
    alice = new_page("alice")
    alice.goto(f"{live_server.url}/projects/{studio['project'].pk}/team/")
    alice.get_by_test_id("create-form-username").fill("erin")
    alice.get_by_test_id("create-form").get_by_role("button").click()
    password = alice.get_by_test_id("one-time-password").inner_text()
    assert get_user_model().objects.get(username="erin").check_password(password)
    alice.get_by_test_id("dialog-ok").click()
    expect(alice.get_by_test_id("member-erin")).to_contain_text("erin")


def test_a_project_admin_is_not_offered_account_creation(live_server, new_page, studio):
    alice = new_page("alice")
    alice.goto(f"{live_server.url}/projects/{studio['project'].pk}/team/")
    expect(alice.get_by_test_id("invite-form")).to_be_visible()
    expect(alice.get_by_test_id("create-form")).to_have_count(0)
    url = f"/api/projects/{studio['project'].pk}/members/new-account/"
    assert fetch(alice, "POST", url, {"username": "bob", "role": "annotator"}) == 403
    assert fetch(alice, "POST", url, {"username": "nobody-yet", "role": "annotator"}) == 403


def test_a_reviewer_sees_the_team_but_cannot_change_roles(live_server, new_page, studio):
    project = studio["project"]
    rachel = new_page("rachel")
    rachel.goto(f"{live_server.url}/projects/{project.pk}/team/")
    expect(rachel.get_by_test_id("role-bob")).to_have_text("annotator")
    expect(rachel.locator("select[data-testid^=role-]")).to_have_count(0)
    expect(rachel.get_by_test_id("invite-form")).to_have_count(0)
    status = fetch(rachel, "PATCH", f"/api/projects/{project.pk}/members/{studio['bob'].pk}/", {"role": "admin"})
    assert status == 403
    assert project.role_of(studio["bob"]) == "annotator"


def test_an_annotator_cannot_open_the_team_page(live_server, new_page, studio):
    project = studio["project"]
    ann = new_page("ann")
    ann.get_by_test_id("filter-project").select_option(str(project.pk))
    expect(ann.get_by_test_id("nav-team")).to_have_count(0)
    ann.goto(f"{live_server.url}/projects/{project.pk}/team/")
    expect(ann.get_by_test_id("team-refused")).to_contain_text("Only the project's reviewers and admins")
    expect(ann.get_by_test_id("members")).to_have_count(0)
    assert fetch(ann, "GET", f"/api/projects/{project.pk}/members/") == 403


def test_an_admin_edits_the_taxonomy_and_the_palette_applies_a_label(live_server, new_page, studio, ingested_capture):
    from segmentation import services
    from segmentation.models import Review

    project = studio["project"]
    for name in ("crouch", "crawl", "roll", "climb", "throw", "catch"):
        services.do_add_label(project, name, "#667788")
    alice = new_page("alice")
    alice.goto(f"{live_server.url}/projects/{project.pk}/team/")
    alice.get_by_test_id("label-name-kick").fill("roundhouse")
    alice.get_by_test_id("label-name-kick").press("Enter")
    expect(alice.get_by_test_id("label-row-roundhouse")).to_be_visible()
    alice.get_by_test_id("label-retire-squat").click()
    expect(alice.get_by_test_id("label-row-squat")).to_have_class("retired")
    alice.get_by_test_id("label-down-walk").click()
    expect(alice.get_by_test_id("taxonomy").locator("tr").first).to_have_attribute("data-testid", "label-row-punch")
    alice.get_by_test_id("new-label-name").fill("cartwheel")
    alice.get_by_test_id("new-label").get_by_role("button").click()
    expect(alice.get_by_test_id("label-row-cartwheel")).to_be_visible()
    assert [label.name for label in project.labels.all()][:2] == ["punch", "walk"]
    alice.get_by_test_id("label-color-punch").fill("#123456")
    expect(alice.locator(".toast", has_text="punch: new colour.")).to_be_visible()
    alice.get_by_test_id("label-hotkey-crouch").select_option("6")
    expect(alice.locator(".toast", has_text="crouch answers to 6.")).to_be_visible()
    assert project.labels.get(name="punch").color == "#123456"

    # Twelve labels in use: the annotator applies one by typing its name in the palette.
    ann = new_page("ann")
    ann.goto(f"{live_server.url}/captures/{ingested_capture.pk}/")
    expect(ann.get_by_test_id("label-roundhouse")).to_be_visible()
    expect(ann.get_by_test_id("label-squat")).to_have_count(0)
    ann.keyboard.press("/")
    ann.get_by_test_id("palette-input").fill("cart")
    expect(ann.get_by_test_id("palette-list").locator("li")).to_have_count(1)
    ann.get_by_test_id("palette-input").press("Enter")
    expect(ann.get_by_test_id("current-segment")).to_contain_text("labelled cartwheel")
    expect(ann.get_by_test_id("save-state")).to_have_text("Saved")
    review = Review.objects.get(capture=ingested_capture, annotator=studio["ann"])
    assert review.segments()[0][3] == "cartwheel"
    # The new hotkey applies its label at once.
    ann.keyboard.press("6")
    expect(ann.get_by_test_id("current-segment")).to_contain_text("labelled crouch")
    # The edit is saved before the test ends: the database is emptied after it, and a save
    # still being written holds a lock on the review's tables.
    expect(ann.get_by_test_id("save-state")).to_have_text("Saved")
