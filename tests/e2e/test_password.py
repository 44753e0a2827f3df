"""A person changes their password from the top bar: a wrong current password or a weak
new one is refused in the dialog with the server's reason; a good one signs their other
sessions out, keeps this one, and is the password they sign in with afterwards."""

from playwright.sync_api import expect

NEW = "quiet-harbour-lantern-42"


def fill(page, current, new, confirm=None):
    page.get_by_test_id("password-current").fill(current)
    page.get_by_test_id("password-new").fill(new)
    page.get_by_test_id("password-confirm").fill(new if confirm is None else confirm)
    page.get_by_test_id("password-save").click()


def test_a_person_changes_their_password_from_the_page(live_server, new_page, studio):
    page = new_page("bob")
    elsewhere = new_page("bob")
    expect(page.locator(".pager")).to_contain_text("capture")
    page.get_by_test_id("change-password").click()
    error = page.get_by_test_id("password-error")

    fill(page, "bob-password", NEW, confirm="something-else")
    expect(error).to_contain_text("differ")
    fill(page, "not-my-password", NEW)
    expect(error).to_have_text("current_password: this is not your current password")
    fill(page, "bob-password", "password123")
    expect(error).to_contain_text("new_password: This password is too common.")
    fill(page, "bob-password", NEW)
    expect(page.get_by_role("dialog")).to_have_count(0)
    expect(page.locator(".toast")).to_contain_text("Password changed")

    page.reload()
    expect(page.locator(".pager")).to_contain_text("capture")  # this session stays signed in
    elsewhere.reload()
    elsewhere.wait_for_url(f"{live_server.url}/login/?next=/")  # the other one does not
    elsewhere.fill("#id_username", "bob")
    elsewhere.fill("#id_password", NEW)
    elsewhere.click("button[type=submit]")
    elsewhere.wait_for_url(f"{live_server.url}/")
    studio["bob"].refresh_from_db()
    assert studio["bob"].check_password(NEW)
    assert page.errors == [] and elsewhere.errors == [], (page.errors, elsewhere.errors)


def test_a_site_admin_resets_a_password_from_the_team_page(live_server, new_page, studio):
    studio["alice"].is_superuser = True
    studio["alice"].save()
    bob = new_page("bob")
    alice = new_page("alice")
    alice.goto(f"{live_server.url}/projects/{studio['project'].pk}/team/")
    expect(alice.get_by_test_id("reset-password-alice")).to_have_count(0)  # not one's own
    alice.get_by_test_id("reset-password-bob").click()
    alice.get_by_test_id("confirm-ok").click()
    password = alice.get_by_test_id("one-time-password").inner_text()
    alice.get_by_test_id("dialog-ok").click()
    studio["bob"].refresh_from_db()
    assert studio["bob"].check_password(password)
    bob.reload()
    bob.wait_for_url(f"{live_server.url}/login/?next=/")
    bob.fill("#id_username", "bob")
    bob.fill("#id_password", password)
    bob.click("button[type=submit]")
    # Signed in with the one-time password, bob first chooses his own.
    bob.wait_for_url(f"{live_server.url}/password/new/?next=/")
    bob.fill("#id_new_password1", NEW)
    bob.fill("#id_new_password2", NEW)
    bob.click("button[type=submit]")
    bob.wait_for_url(f"{live_server.url}/")
    expect(bob.locator(".pager")).to_contain_text("capture")
    studio["bob"].refresh_from_db()
    assert studio["bob"].check_password(NEW) and not studio["bob"].check_password(password)
    assert alice.errors == [] and bob.errors == [], (alice.errors, bob.errors)


def test_a_project_admin_is_not_offered_password_resets(live_server, new_page, studio):
    alice = new_page("alice")
    alice.goto(f"{live_server.url}/projects/{studio['project'].pk}/team/")
    expect(alice.get_by_test_id("member-bob")).to_be_visible()
    expect(alice.get_by_test_id("reset-password-bob")).to_have_count(0)
