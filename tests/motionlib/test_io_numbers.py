"""The vectorised number parser reads exactly what float() reads, or declines (None)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from motionlib.io.numbers import parse_decimal_lines, token_bounds, token_values

deterministic = settings(derandomize=True, max_examples=150, deadline=None)

digits = st.text("0123456789", min_size=1, max_size=8)
decimal = st.builds(
    lambda sign, whole, frac, exp: sign + whole + frac + exp,
    st.sampled_from(["", "-", "+"]),
    digits,
    st.one_of(st.just(""), st.just("."), digits.map(lambda d: "." + d)),
    st.one_of(st.just(""), st.builds(lambda e, s, d: e + s + d, st.sampled_from("eE"),
                                     st.sampled_from(["", "-", "+"]),
                                     st.text("0123456789", min_size=1, max_size=2))),
)


@deterministic
@given(st.lists(st.lists(decimal, min_size=1, max_size=6), min_size=1, max_size=8),
       st.sampled_from([" ", "\t", "  "]), st.sampled_from(["\n", "\r\n"]))
def test_it_matches_float_on_well_formed_numbers(rows, sep, newline):
    text = newline.join(sep.join(row) for row in rows) + newline
    parsed = parse_decimal_lines(text.encode(), chunk_bytes=16)
    expected = np.array([float(t) for row in rows for t in row])
    assert parsed is not None
    values, per_line = parsed
    np.testing.assert_array_equal(values, expected)
    assert list(per_line[per_line > 0]) == [len(row) for row in rows]


@deterministic
@given(st.text("0123456789.-+eE x", min_size=1, max_size=12))
def test_it_never_disagrees_with_float(token):
    b = np.frombuffer(token.encode(), dtype=np.uint8)
    starts, ends = token_bounds(b)
    values = token_values(b, starts, ends)
    if values is None:
        return
    expected = [float(t) for t in token.split()]  # raises if we accepted a non-number
    np.testing.assert_array_equal(values, expected)


def test_it_reads_the_cmu_exponent_style():
    text = b"rclavicle -1.758e-015 -2.51463e-014\n"
    b = np.frombuffer(text, dtype=np.uint8)
    starts, ends = token_bounds(b)
    assert token_values(b, starts, ends) is None  # the bone name is not a number
    values = token_values(b, starts[1:], ends[1:])
    assert values.tolist() == [-1.758e-15, -2.51463e-14]


def test_it_declines_nan_infinity_and_text():
    for text in (b"1 nan 2\n", b"inf\n", b"1,5\n", b"12a\n", b"1.2.3\n", b"--1\n"):
        assert parse_decimal_lines(text) is None, text
