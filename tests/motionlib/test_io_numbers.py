"""The compiled number reader reads exactly what float() reads, or declines (None)."""

import struct

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from motionlib.io.numbers import read_rows

deterministic = settings(derandomize=True, max_examples=300, deadline=None)

digits = st.text("0123456789", min_size=1, max_size=24)
decimal = st.builds(
    lambda sign, whole, frac, exp: sign + whole + frac + exp,
    st.sampled_from(["", "-", "+"]),
    digits,
    st.one_of(st.just(""), st.just("."), digits.map(lambda d: "." + d)),
    st.one_of(st.just(""), st.builds(lambda e, s, d: e + s + d, st.sampled_from("eE"),
                                     st.sampled_from(["", "-", "+"]),
                                     st.text("0123456789", min_size=1, max_size=3))),
)


def bits(values) -> list[bytes]:
    """Exact bit patterns, so -0.0 and 0.0 differ and nothing is compared with a tolerance."""
    return [struct.pack("<d", v) for v in values]


def finite(token: str) -> bool:
    return np.isfinite(float(token))


@deterministic
@given(st.lists(st.lists(decimal.filter(finite), min_size=3, max_size=3), min_size=1,
                max_size=8),
       st.sampled_from([" ", "\t", "  ", " \t"]), st.sampled_from(["\n", "\r\n", "\n\n"]))
def test_it_matches_float_bit_for_bit_on_well_formed_rows(rows, sep, newline):
    text = newline.join(sep.join(row) for row in rows) + newline
    values = read_rows(text.encode(), 0, len(rows), 3)
    assert values is not None
    assert bits(values.ravel()) == bits(float(t) for row in rows for t in row)


short = st.builds(lambda sign, whole, frac: sign + whole + frac, st.sampled_from(["", "-", "+"]),
                  st.text("0123456789", min_size=1, max_size=9),
                  st.one_of(st.just(""), st.text("0123456789", max_size=9).map(lambda d: "." + d)))


@deterministic
@given(st.lists(short, min_size=12, max_size=12), st.sampled_from([" ", "\t", " \r"]))
def test_it_matches_float_on_short_decimals_read_a_word_at_a_time(tokens, sep):
    # Up to 7 digits either side of the dot take a word-wide path when 17 bytes follow; 8 or
    # 9 digits, an empty side and the last tokens of the text take the byte loop.
    text = sep.join(tokens[:6]) + "\n" + sep.join(tokens[6:]) + "\n"
    values = read_rows(text.encode(), 0, 2, 6)
    assert values is not None
    assert bits(values.ravel()) == bits(float(t) for t in tokens)


@deterministic
@given(st.floats(allow_nan=False, allow_infinity=False))
def test_it_round_trips_every_double_through_repr(x):
    for text in (repr(x), f"{x:.17e}", f"{x:.6f}"):
        values = read_rows(text.encode(), 0, 1, 1)
        assert values is not None and bits(values[0]) == bits([float(text)]), text


@deterministic
@given(st.text("0123456789.-+eE x\t", min_size=1, max_size=14))
def test_it_never_disagrees_with_float(text):
    values = read_rows(text.encode(), 0, 1, max(len(text.split()), 1))
    if values is None:
        return
    expected = [float(t) for t in text.split()]  # raises if we accepted a non-number
    assert bits(values.ravel()) == bits(expected)


@pytest.mark.parametrize("text", [
    "0", "-0", "-0.0", "+3.", ".5", "-.5", "007", "0.000123", "1e22", "1e23", "9007199254740993",
    "123456789012345678901234567890", "0.1e-400", "1e-320", "-2.51463e-014", "4.9e-324",
    "1.7976931348623157e308", "0e999", "0.00000000000000000000000000000000000001",
])
def test_it_reads_edge_cases_exactly(text):
    values = read_rows(text.encode(), 0, 1, 1)
    assert values is not None and bits(values[0]) == bits([float(text)])


@pytest.mark.parametrize("text", [
    b"1 nan 2\n", b"inf\n", b"1e999\n", b"1,5\n", b"12a\n", b"1.2.3\n", b"--1\n", b".\n",
    b"1e\n", b"1e+\n", b"-\n", b"1_000\n", b"1\x002\n", b"0x10\n",
])
def test_it_declines_nan_infinity_and_text(text):
    assert read_rows(text, 0, 1, len(text.split())) is None, text


def test_it_declines_rows_of_another_shape():
    text = b"1 2 3\n\n4 5 6\r\n"
    assert read_rows(text, 0, 2, 3).tolist() == [[1, 2, 3], [4, 5, 6]]
    assert read_rows(text, 0, 3, 3) is None  # fewer lines than declared
    assert read_rows(text, 0, 1, 3) is None  # more lines than declared
    assert read_rows(b"1 2 3\n4 5\n", 0, 2, 3) is None  # a short line
    assert read_rows(b"1 2 3 4\n", 0, 1, 3) is None  # a long line
    assert read_rows(b"x\n1 2 3\n", 2, 1, 3).tolist() == [[1, 2, 3]]  # from an offset


def test_it_reads_the_cmu_exponent_style():
    assert read_rows(b"rclavicle -1.758e-015\n", 0, 1, 2) is None  # a bone name is no number
    values = read_rows(b"-1.758e-015 -2.51463e-014\n", 0, 1, 2)
    assert values.tolist() == [[-1.758e-15, -2.51463e-14]]


def test_it_reads_a_real_take_as_float_does(bvh_13_29):
    data = open(bvh_13_29, "rb").read()
    body = data.index(b"\n", data.index(b"Frame Time")) + 1
    values = read_rows(data, body, 4593, 96)
    expected = [float(t) for t in data[body:].split()]
    assert values is not None and bits(values.ravel()) == bits(expected)
