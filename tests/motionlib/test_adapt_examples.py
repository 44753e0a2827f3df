"""The examples CSV of ``python -m motionlib segment --examples`` and its errors."""

import json

import pytest

from motionlib import synth, write_bvh
from motionlib.adapt import ExampleError, read_examples
from motionlib.cli import main

FPS = 60.0


@pytest.fixture(scope="module")
def takes(tmp_path_factory):
    """Two synthetic BVH takes in one folder with their true cuts."""
    folder = tmp_path_factory.mktemp("examples")
    out = []
    for seed in (1, 2):
        take, segments = synth.generate(seed=seed, fps=FPS, duration=30.0)
        write_bvh(take, folder / f"take{seed}.bvh")
        out.append((f"take{seed}.bvh", [start for start, _, _ in segments[1:]], take.n_frames))
    return folder, out


def _csv(folder, text, name="examples.csv"):
    path = folder / name
    path.write_text(text)
    return path


def test_it_reads_example_takes_relative_to_the_csv(takes):
    folder, rows = takes
    lines = ["file,asf,cuts"] + [f"{f},,{' '.join(map(str, cuts))}" for f, cuts, _ in rows]
    examples = read_examples(_csv(folder, "\n".join(lines) + "\n"))
    assert [ex[1].tolist() for ex in examples] == [cuts for _, cuts, _ in rows]
    assert [ex[0].n_frames for ex in examples] == [n for _, _, n in rows]


def test_it_reads_a_spreadsheet_csv_with_a_byte_order_mark_and_crlf_lines(takes):
    folder, rows = takes
    path = folder / "excel.csv"
    text = "file,asf,cuts\r\n" + f"{rows[0][0]},,{' '.join(map(str, rows[0][1]))}\r\n"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode())
    [(take, cuts)] = read_examples(path)
    assert cuts.tolist() == rows[0][1] and take.n_frames == rows[0][2]


def test_it_names_the_line_of_a_cut_that_is_not_a_number(takes):
    folder, rows = takes
    path = _csv(folder, f"file,asf,cuts\n{rows[0][0]},,120 2x0\n")
    with pytest.raises(ExampleError, match=r"examples.csv:2: cut '2x0' is not a whole frame"):
        read_examples(path)


def test_it_refuses_a_csv_without_the_header(takes):
    folder, rows = takes
    with pytest.raises(ExampleError, match=r"examples.csv:1: expected the header file,asf,cuts"):
        read_examples(_csv(folder, f"{rows[0][0]},,120\n"))


def test_it_refuses_a_row_with_missing_fields(takes):
    folder, rows = takes
    path = _csv(folder, f"file,asf,cuts\n{rows[0][0]},,120\n{rows[1][0]},120\n")
    with pytest.raises(ExampleError, match=r"examples.csv:3: expected 3 fields"):
        read_examples(path)


def test_it_names_an_unreadable_example_take(takes):
    folder, rows = takes
    (folder / "broken.bvh").write_text("HIERARCHY\nROOT Hips\n")
    path = _csv(folder, f"file,asf,cuts\n{rows[0][0]},,120\nbroken.bvh,,100\n")
    with pytest.raises(ExampleError, match=r"examples.csv:3: cannot read broken.bvh"):
        read_examples(path)


def test_it_names_a_cut_outside_its_take(takes):
    folder, rows = takes
    name, _, n = rows[0]
    path = _csv(folder, f"file,asf,cuts\n{name},,100 {n + 10}\n")
    with pytest.raises(ExampleError, match=rf"examples.csv:2: cut {n + 10} is outside {name}"):
        read_examples(path)


def test_it_segments_a_take_adapted_to_the_examples_as_json(takes, capsys):
    folder, rows = takes
    path = _csv(folder, f"file,asf,cuts\n{rows[0][0]},,{' '.join(map(str, rows[0][1]))}\n")
    target = folder / rows[1][0]
    assert main(["segment", str(target), "--examples", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["n_frames"] == rows[1][2]
    assert out["adapted_from"] == {"takes": 1, "cuts": len(rows[0][1])}
    assert out["cuts"] and all(set(c) == {"frame", "confidence"} for c in out["cuts"])


def test_it_exits_2_with_one_line_on_a_bad_examples_csv(takes, capsys):
    folder, rows = takes
    path = _csv(folder, "file,asf,cuts\nmissing.bvh,,100\n", name="bad.csv")
    assert main(["segment", str(folder / rows[1][0]), "--examples", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "bad.csv:2: cannot read missing.bvh" in err


def test_it_says_in_the_table_what_the_cuts_were_adapted_from(takes, capsys):
    folder, rows = takes
    path = _csv(folder, f"file,asf,cuts\n{rows[0][0]},,{' '.join(map(str, rows[0][1]))}\n")
    assert main(["segment", str(folder / rows[1][0]), "--examples", str(path)]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.endswith(f"adapted from 1 example take with {len(rows[0][1])} cuts)")


def test_it_refuses_examples_for_a_method_that_does_not_adapt(takes, capsys):
    folder, rows = takes
    path = _csv(folder, f"file,asf,cuts\n{rows[0][0]},,100\n")
    assert main(["segment", str(folder / rows[1][0]), "--method", "ppca",
                 "--examples", str(path)]) == 2
    assert "only the default method adapts" in capsys.readouterr().err
