import { describe, expect, it } from "vitest";
import { ApiError, errorText, isLoggedOut, readCookie } from "../src/api/client";
import { filtersFrom, queryOf } from "../src/captures/list";
import { pairFiles } from "../src/captures/upload";
import { failure, match, registerRoute } from "../src/router";
import { eventDetail } from "../src/review/events";
import { columnExtremes, finiteRange, readableOn } from "../src/review/timeline";

describe("api client", () => {
  it("test_it_reads_the_csrf_cookie_among_others", () => {
    expect(readCookie("sessionid=abc; csrftoken=x%3Dy; theme=dark", "csrftoken")).toBe("x=y");
    expect(readCookie("sessionid=abc", "csrftoken")).toBeNull();
  });

  it("test_it_shows_the_servers_detail_or_each_field_error", () => {
    expect(errorText(409, { detail: "stale version 3", review: {} })).toBe("stale version 3");
    expect(errorText(400, { params: { sigma: ["must be >= 0, got -1"] } })).toBe("params.sigma: must be >= 0, got -1");
    expect(errorText(502, "<html>Bad gateway</html>")).toBe("The server answered 502.");
  });

  it("test_it_sends_people_to_login_only_when_they_are_logged_out", () => {
    expect(isLoggedOut(403, { detail: "Authentication credentials were not provided." })).toBe(true);
    expect(isLoggedOut(403, { detail: "Only the project's reviewers and admins see every review." })).toBe(false);
    expect(isLoggedOut(401, null)).toBe(true);
  });
});

describe("capture list", () => {
  it("test_it_round_trips_filters_through_the_query_string", () => {
    const f = filtersFrom("?project=2&status=ready&search=walk%20fast&page=3");
    expect(f).toEqual({ project: "2", status: "ready", search: "walk fast", page: 3 });
    expect(queryOf(f)).toBe("?project=2&status=ready&search=walk+fast&page=3");
    expect(queryOf(filtersFrom(""))).toBe("");
  });

  it("test_it_pairs_each_amc_with_its_subjects_asf", () => {
    const file = (name: string) => new File(["x"], name);
    const { items, problems } = pairFiles([file("13_29.amc"), file("86_01.amc"), file("13.asf"), file("86.asf"), file("walk.bvh")]);
    expect(items.map((i) => [i.file.name, i.asf?.name ?? null])).toEqual([["13_29.amc", "13.asf"], ["86_01.amc", "86.asf"], ["walk.bvh", null]]);
    expect(problems).toEqual([]);
  });

  it("test_it_explains_files_it_cannot_upload", () => {
    const file = (name: string) => new File(["x"], name);
    expect(pairFiles([file("13_29.amc"), file("notes.txt")]).problems).toEqual([
      "13_29.amc: an .amc needs its skeleton; drop the matching .asf with it.",
      "notes.txt: not a take Cutroom reads (.bvh, .fbx, .amc with its .asf, .c3d, .tsv or .csv).",
    ]);
  });

  it("test_it_uploads_point_takes_alone", () => {
    const file = (name: string) => new File(["x"], name);
    const { items, problems } = pairFiles([file("HDM_bd_05-01_01_120.C3D"), file("subject1_run1.tsv"), file("s01_e01.csv")]);
    expect(items.map((i) => [i.file.name, i.asf])).toEqual([["HDM_bd_05-01_01_120.C3D", null], ["subject1_run1.tsv", null], ["s01_e01.csv", null]]);
    expect(problems).toEqual([]);
  });

  it("test_it_uploads_an_fbx_alone", () => {
    const file = (name: string) => new File(["x"], name);
    const { items, problems } = pairFiles([file("samba.FBX")]);
    expect(items.map((i) => [i.file.name, i.asf])).toEqual([["samba.FBX", null]]);
    expect(problems).toEqual([]);
  });
});

describe("router", () => {
  it("test_it_titles_a_refusal_by_role_as_a_refusal_not_a_failure", () => {
    const refused = failure(new ApiError(403, "Only the project's reviewers and admins see its dashboard.", null));
    expect(refused).toEqual({ title: "Not allowed", message: "Only the project's reviewers and admins see its dashboard.", refusal: true });
    expect(failure(new ApiError(404, "Not found.", null)).title).toBe("Not found");
    expect(failure(new ApiError(500, "The server answered 500.", null))).toMatchObject({ title: "Something went wrong", refusal: false });
    expect(failure(new Error("network down")).title).toBe("Something went wrong");
  });

  it("test_it_matches_routes_with_or_without_the_trailing_slash", () => {
    const render = async () => () => {};
    registerRoute("/test-captures/:id/", render);
    expect(match("/test-captures/12/")?.params).toEqual({ id: "12" });
    expect(match("/test-captures/12")?.params).toEqual({ id: "12" });
    expect(match("/test-captures/12/extra")).toBeNull();
  });
});

describe("timeline helpers", () => {
  it("test_it_scales_signals_by_their_finite_range", () => {
    expect(finiteRange([3, NaN, -1, Infinity, 2])).toEqual([-1, 3]);
    expect(finiteRange([2, 2])).toEqual([1.5, 2.5]);
    expect(finiteRange([])).toEqual([0, 1]);
  });

  it("test_it_reduces_dense_signals_to_a_min_max_per_pixel_column", () => {
    const signal = { name: "q", start: 0, step: 1, values: [0, 5, 1, 9, 2, 3] };
    const columns = columnExtremes(signal, 0, 5, (i) => i / 2, 3);
    expect(columns).toEqual([[0, 5], [1, 9], [2, 3]]);
  });

  it("test_it_picks_readable_text_on_label_colours", () => {
    expect(readableOn("#ffeb3b")).toBe("#111418");
    expect(readableOn("#1a237e")).toBe("#ffffff");
  });
});

describe("audit log lines", () => {
  it("test_it_describes_each_kind_of_event_in_words", () => {
    expect(eventDetail({ action: "create", before: null, after: { run: 3, candidates: 12 } })).toBe("12 candidates");
    expect(eventDetail({ action: "delete", before: { frame: 2088, fate: "pending" }, after: { frame: 2088, fate: "deleted" } })).toBe("frame 2088: pending → deleted");
    expect(eventDetail({ action: "move", before: { frame: 700, fate: "pending" }, after: { frame: 760, fate: "moved" } })).toBe("frame 700 → 760");
    expect(eventDetail({ action: "insert", before: null, after: { frame: 3018, fate: "accepted" } })).toBe("at frame 3018");
    expect(eventDetail({ action: "label", before: { index: 0, label: null }, after: { index: 0, label: "walk" } })).toBe("segment 1: — → walk");
    expect(eventDetail({ action: "candidates", before: null, after: { run: 4, candidates: 9 } })).toBe("9 candidates arrived");
  });
});
