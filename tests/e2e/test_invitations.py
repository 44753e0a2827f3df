"""An invitation shows on the invitee's capture list; accepting it joins the project."""

from playwright.sync_api import expect


def test_the_invitee_accepts_an_invitation_from_the_capture_list(live_server, new_page, studio, screenshots):
    from django.contrib.auth import get_user_model

    from segmentation import services

    dana = get_user_model().objects.create_user("dana", password="dana-password")
    services.do_add_member(studio["project"], studio["alice"], "dana", "reviewer")
    assert studio["project"].role_of(dana) is None

    page = new_page("dana")
    invitation = page.get_by_test_id("invitation")
    expect(invitation).to_have_text("alice invites you to Studio A as reviewer.AcceptDecline")
    page.screenshot(path=str(screenshots / "invitation.png"))
    invitation.get_by_role("button", name="Accept").click()
    expect(page.get_by_test_id("filter-project")).to_contain_text("Studio A")
    expect(page.get_by_test_id("invitations")).to_be_hidden()
    assert studio["project"].role_of(dana) == "reviewer"


def test_declining_hides_the_invitation_and_joins_nothing(live_server, new_page, studio):
    from django.contrib.auth import get_user_model

    from segmentation import services

    dana = get_user_model().objects.create_user("dana", password="dana-password")
    services.do_add_member(studio["project"], studio["alice"], "dana", "annotator")
    page = new_page("dana")
    page.get_by_test_id("invitation").get_by_role("button", name="Decline").click()
    expect(page.get_by_test_id("invitations")).to_be_hidden()
    expect(page.get_by_test_id("filter-project")).not_to_contain_text("Studio A")
    assert studio["project"].role_of(dana) is None
