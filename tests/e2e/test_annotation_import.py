"""Importing an ELAN file into a review through the page's file dialog, choosing its tier
and mapping a label the project lacks, then taking the import back with one undo; and the
review exported again as ELAN, read by pympi-ling (issue 49)."""

import pympi
from playwright.sync_api import expect

from tests.e2e.test_review_page import ReviewScreen


def elan_file(path):
    """An ELAN document as pympi writes it: tier "moves" (walk 0-5 s, Jab 10-15 s, Walk
    20-25 s) and tier "notes"."""
    eaf = pympi.Elan.Eaf()
    eaf.add_tier("moves")
    eaf.add_annotation("moves", 0, 5000, "walk")
    eaf.add_annotation("moves", 10000, 15000, "Jab")
    eaf.add_annotation("moves", 20000, 25000, "Walk ")
    eaf.add_tier("notes")
    eaf.add_annotation("notes", 1000, 2000, "warm-up")
    eaf.to_file(str(path))
    return path


def segments(review):
    return [(s["start"], s["stop"], s["label"]) for s in review["segments"]]


def test_an_annotator_imports_an_elan_tier_through_the_dialog_and_undoes_it(live_server, new_page, ingested_capture, studio, tmp_path):
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    n = ingested_capture.n_frames
    assert n == 4800  # 40 s at 120 fps

    page.get_by_test_id("import-annotations").click()
    with page.expect_file_chooser() as chooser:
        page.get_by_test_id("import-file").click()
    chooser.value.set_files(str(elan_file(tmp_path / "session.eaf")))

    # The file has two tiers: the first is shown until one is chosen.
    source = page.get_by_test_id("import-source")
    expect(source.locator("option")).to_have_text(["moves", "notes"])
    source.select_option("notes")
    expect(page.get_by_test_id("import-summary")).to_have_text("1 segment (1 labelled) from session.eaf.")
    expect(page.get_by_test_id("import-ok")).to_be_disabled()  # "warm-up" is no label of the project
    source.select_option("moves")
    expect(page.get_by_test_id("import-summary")).to_have_text("3 segments (3 labelled) from session.eaf.")
    expect(page.get_by_test_id("import-unknown")).to_contain_text("2 labels are not in this project")
    # "Walk" differs from walk only in case: proposed; "Jab" must be chosen.
    expect(page.locator("[data-testid=import-map][data-label='Walk']")).to_have_value("walk")
    jab = page.locator("[data-testid=import-map][data-label='Jab']")
    expect(jab).to_have_value("")
    expect(page.get_by_test_id("import-ok")).to_be_disabled()
    jab.select_option("punch")
    page.get_by_test_id("import-ok").click()
    expect(page.get_by_role("dialog")).to_have_count(0)
    screen.saved()

    review = screen.review()
    assert segments(review) == [(0, 600, "walk"), (600, 1200, None), (1200, 1800, "punch"),
                                (1800, 2400, None), (2400, 3000, "walk"), (3000, n, None)]
    events = screen.events()
    assert [e["action"] for e in events] == ["create", "import"]
    assert events[1]["user"] == "ann" and events[1]["after"]["source"] == "moves"
    assert events[1]["after"]["mapping"] == {"Jab": "punch", "Walk": "walk"}
    expect(page.get_by_test_id("events").locator("li").first).to_contain_text("3 segments from session.eaf (moves)")
    assert not studio["project"].labels.filter(name__in=["Jab", "Walk"]).exists()

    # Exported as ELAN, the review reads back in pympi as the same frames.
    with page.expect_download() as download:
        page.get_by_test_id("export-annotations").select_option("eaf")
    exported = tmp_path / "exported.eaf"
    download.value.save_as(exported)
    tier = pympi.Elan.Eaf(str(exported)).get_annotation_data_for_tier("ann")
    assert [(a, b, v) for a, b, v in tier if v] == [(0, 5000, "walk"), (10000, 15000, "punch"),
                                                     (20000, 25000, "walk")]

    # One undo takes the whole import back: the detector's candidates, pending again.
    expect(page.get_by_test_id("undo")).to_be_enabled()
    page.keyboard.press("z")
    screen.saved()
    after_undo = screen.review()
    assert {c["fate"] for c in after_undo["cuts"] if c["origin"] == "candidate"} == {"pending"}
    assert all(s["label"] is None for s in after_undo["segments"])
    assert page.errors == []


def test_a_file_the_page_cannot_import_is_named_in_the_dialog(live_server, new_page, ingested_capture, studio, tmp_path):
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    bad = tmp_path / "labels.csv"
    bad.write_text("take,start,end,label\nwarmup_session,0,100,walk\nwarmup_session,50,9000,walk\n")
    page.get_by_test_id("import-annotations").click()
    with page.expect_file_chooser() as chooser:
        page.get_by_test_id("import-file").click()
    chooser.value.set_files(str(bad))
    expect(page.get_by_test_id("import-error")).to_have_text(
        "labels.csv: line 3: frames 50..9000 are outside the take (0..4800, end exclusive)")
    expect(page.get_by_test_id("import-ok")).to_be_disabled()
    page.get_by_test_id("import-cancel").click()
    assert screen.review()["id"] is None  # nothing was started, nothing written


def test_a_reviewer_imports_a_csv_into_gold_from_the_adjudication_page(live_server, new_page, ingested_capture, studio, tmp_path):
    from segmentation.models import Adjudication
    from tests.segmentation.test_library import submit_review

    submit_review(ingested_capture, studio["ann"], [1200], ["walk", "punch"])
    labels = tmp_path / "gold.csv"
    labels.write_text("take;start_timecode;end_timecode;label\n"
                      "warmup_session;00:00:00:000;00:00:10:000;walk\n"
                      "warmup_session;00:00:10:000;00:00:40:000;squat\n")
    page = new_page("rachel")
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/adjudicate/")
    page.get_by_test_id("import-gold").click()
    expect(page.get_by_role("dialog")).to_contain_text("Import annotations into gold")
    with page.expect_file_chooser() as chooser:
        page.get_by_test_id("import-file").click()
    chooser.value.set_files(str(labels))
    expect(page.get_by_test_id("import-summary")).to_have_text("2 segments (2 labelled) from gold.csv.")
    page.get_by_test_id("import-ok").click()
    expect(page.get_by_role("dialog")).to_have_count(0)
    expect(page.get_by_test_id("track-gold").locator(".tier-seg")).to_have_count(2)
    gold = Adjudication.objects.get(capture=ingested_capture)
    assert (gold.cuts, gold.label_names(), gold.adjudicator.username) == ([1200], ["walk", "squat"], "rachel")
    assert page.errors == []
