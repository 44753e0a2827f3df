"""Reading capture files as bytes with their line ends made uniform."""

from __future__ import annotations

import re
from pathlib import Path

_LONE_CR = re.compile(rb"\r(?!\n)")
UTF8_BOM = b"\xef\xbb\xbf"


def read_lines_bytes(path) -> bytes:
    """The bytes of ``path`` without a UTF-8 byte-order mark, with classic Mac line ends (a
    CR alone) turned into LF.

    Spreadsheets on Windows save CSV with the mark; left in, it would become part of the
    first word ("\ufeffframe"), and a valid file would be refused for a reason no one sees.

    Every reader counts lines by LF; a file saved with CR alone would otherwise be one long
    line, and its error messages would point at the wrong place for the wrong reason.
    CRLF is left as it is (the CR is whitespace to the readers).
    """
    data = Path(path).read_bytes()
    return lone_cr_to_lf(data[len(UTF8_BOM):] if data.startswith(UTF8_BOM) else data)


def lone_cr_to_lf(data: bytes) -> bytes:
    """``data`` with each CR not followed by LF turned into LF."""
    if b"\r" in data and data.count(b"\r") != data.count(b"\r\n"):
        data = _LONE_CR.sub(b"\n", data)
    return data


# What a spreadsheet reads as the start of a formula in a cell (OWASP, "CSV Injection"):
# = + - @, a tab or line end, and their full-width forms, which some spreadsheets fold.
FORMULA_START = ("=", "+", "-", "@", "\t", "\r", "\n", "\uff1d", "\uff0b", "\uff0d", "\uff20")


def spreadsheet_safe(cell: str) -> str:
    """``cell`` with a ``'`` before it when a spreadsheet would take it for a formula.

    Names written into CSV files (capture, label, point names) come from whoever uploaded
    or typed them: ``=HYPERLINK(...)`` or ``@SUM(...)`` must open as text, not run. The
    quote is the one spreadsheets themselves use for "text as typed" (OWASP's advice);
    :func:`spreadsheet_text` takes it off again when such a file is read back.
    """
    return "'" + cell if cell.startswith(FORMULA_START) else cell


def spreadsheet_text(cell: str) -> str:
    """The inverse of :func:`spreadsheet_safe`: ``'=x`` -> ``=x``; anything else as it is."""
    return cell[1:] if cell.startswith("'") and cell[1:].startswith(FORMULA_START) else cell
