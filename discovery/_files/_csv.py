"""Reading numeric CSV records, shared by both systems: encodings (UTF-8 with or without
BOM, UTF-16, Latin-1), separators (comma, semicolon, tab, whitespace), decimal commas, and
one clear line for a bad file."""

import csv
import os
import stat
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, VidiTypeError
from ._io import short

__all__ = ["CsvRows", "read_csv_rows", "parse_column", "MAX_RECORD_BYTES"]

#: the largest data file read: about two million rows of seven columns (some 2,500 drive
#: periods of the paper's machine at 20 kHz); a record is held as text, rows and arrays at
#: once, about ten times its size in memory
MAX_RECORD_BYTES = 200 * 2**20


@dataclass(frozen=True)
class CsvRows:
    """The rows of a CSV file as read (:func:`read_csv_rows`), not yet numbers.

    Attributes
    ----------
    header : list of str
        The column names, stripped.
    body : list of (int, list of str)
        The data rows: ``(line number, fields)``.
    decimal_comma : bool
        Whether the numbers are written with decimal commas.
    notes : tuple of str
        What was noticed reading it (the encoding, decimal commas).
    """

    header: list
    body: list
    decimal_comma: bool
    notes: tuple


def read_csv_rows(path, needs):
    """The one CSV reader of both systems.

    UTF-8 (with or without a byte-order mark) or UTF-16 with one; ``,``, ``;`` or tab as
    the separator (from the header); ``#`` comment lines and blank lines skipped; decimal
    commas with ``;`` or tab.

    Parameters
    ----------
    path : str or os.PathLike
    needs : str
        Names the columns for the messages (``"t and F"``).

    Returns
    -------
    CsvRows
    """
    if not isinstance(path, str | os.PathLike):  # an int would be read as a file descriptor
        raise VidiTypeError(
            f"the data file must be a path (text or os.PathLike); got {type(path).__name__} "
            f"{str(path)[:40]!r}"
        )
    name = short(path)
    text, notes = _read_text(path, name)
    lines = [
        (i + 1, ln)
        for i, ln in enumerate(text.splitlines())
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not lines:
        raise InputError(f"data file {name!r} is empty; it needs a header with {needs}")
    delim = _sniff(lines[0][1])
    rows = []
    for ln, line in lines:  # one record per line (no quoted line breaks in numbers)
        try:
            rows.append(next(csv.reader([line], delimiter=delim), []))
        except csv.Error as exc:
            raise InputError(
                f"data file {name!r}: line {ln} is not a readable CSV row "
                f"({exc}); save the file as CSV with a header row"
            ) from None
    header = [h.strip() for h in rows[0]]
    body = list(zip((ln for ln, _ in lines[1:]), rows[1:], strict=True))
    for ln, row in body:  # a value without a column: a shifted or merged row
        if len(row) > len(header) and any(c.strip() for c in row[len(header) :]):
            raise InputError(
                f"data file {name!r}: line {ln} has {len(row)} fields under a header of "
                f"{len(header)} columns; fix the row (a separator too many?) or name the "
                "extra column in the header"
            )
    if not body:
        raise InputError(f"data file {name!r} has a header but no data rows")
    decimal_comma = delim != "," and any("," in c for _, r in body[:50] for c in r)
    if decimal_comma:
        notes += ("decimal commas read as decimal points",)
    return CsvRows(header=header, body=body, decimal_comma=decimal_comma, notes=notes)


def _read_text(path, name):
    """The file's text (UTF-8 with or without BOM, or UTF-16 with BOM) and notes."""
    if not name.strip():
        raise InputError("the data file name is empty; give a CSV file such as D.csv")
    try:
        st = os.stat(path)
        if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode):
            raise InputError(f"data file {name!r} is a device, not a file; give a CSV file")
        size = st.st_size
        if size > MAX_RECORD_BYTES:
            raise InputError(
                f"data file {name!r} is {size / 2**20:.0f} MB; records up to "
                f"{MAX_RECORD_BYTES // 2**20} MB are read (about two million rows of seven "
                "columns, held in memory about ten times over): cut it to the span the "
                "question needs (20-50 drive periods are plenty) or downsample it"
            )
        with open(path, "rb") as fh:
            raw = fh.read()
    except FileNotFoundError:
        raise InputError(f"data file {name!r} does not exist; check the path") from None
    except IsADirectoryError:
        raise InputError(
            f"data file {name!r} is a directory; give the CSV file itself, e.g. "
            f"{os.path.join(name, 'D.csv')!r}"
        ) from None
    except PermissionError:
        raise InputError(
            f"data file {name!r} cannot be read (permission denied); fix its "
            "permissions or copy it somewhere readable"
        ) from None
    except OSError as exc:
        raise InputError(
            f"cannot read data file {name!r} ({exc.strerror or exc}); check the path"
        ) from None
    notes = ()
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        try:
            text = raw.decode("utf-16")
        except UnicodeDecodeError:
            raise InputError(
                f"data file {name!r} starts with a UTF-16 byte-order mark but is "
                "not valid UTF-16; re-save it as UTF-8 CSV"
            ) from None
        notes = ("read as UTF-16 (byte-order mark)",)
    else:
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            raise InputError(
                f"data file {name!r} is not UTF-8 text (byte 0x{raw[exc.start]:02x} "
                f"at offset {exc.start}); re-save it as UTF-8 (spreadsheets: "
                "'CSV UTF-8'; or iconv -f latin1 -t utf-8)"
            ) from None
    if "\x00" in text:
        raise InputError(
            f"data file {name!r} contains NUL bytes: it is binary (or UTF-16 "
            "without a byte-order mark), not CSV text; export it as CSV (UTF-8)"
        )
    return text, notes


def _sniff(header_line):
    """The separator of the header line: the most frequent of tab, ';' and ','."""
    counts = [(header_line.count(c), -k, c) for k, c in enumerate(("\t", ";", ","))]
    n, _, c = max(counts)
    return c if n else ","


def parse_column(rows, key, j, *, name, limits):
    """Column ``j`` of the data rows as floats, with a line-numbered error for a missing,
    non-numeric, non-finite or out-of-range cell.

    Parameters
    ----------
    rows : CsvRows
    key : str
        Our name of the column (looked up in ``limits``).
    j : int
        Its index in ``rows.header``.
    name : str
        The file, as the messages call it.
    limits : dict
        ``{key: (bound, unit)}``: values beyond ``|bound|`` are refused.

    Returns
    -------
    ndarray of shape (n_rows,)
    """
    hname, body = rows.header[j], rows.body
    cells = []
    for ln, row in body:
        if j >= len(row):
            raise InputError(
                f"data file {name!r}: line {ln} has {len(row)} field(s), no value "
                f"for column {hname}; every row needs a value in every column"
            )
        cells.append(row[j].strip())
    arr = np.array(cells, dtype=str)
    if rows.decimal_comma:
        arr = np.char.replace(arr, ",", ".")
    try:
        v = arr.astype(float)
    except (ValueError, OverflowError):
        for (ln, _), c in zip(body, arr, strict=True):
            try:
                float(c)
            except ValueError:
                what = "is empty" if not c else f"has a non-numeric value {c[:20]!r}"
                raise InputError(
                    f"data file {name!r}: column {hname} {what} at line {ln}; "
                    "every row needs a number (remove the row or fill it)"
                ) from None
        raise InputError(
            f"data file {name!r}: column {hname} cannot be read as numbers; "
            "every row needs a number"
        ) from None
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        raise InputError(
            f"data file {name!r}: column {hname} has the non-finite value "
            f"{cells[bad[0]][:20]!r} at line {body[bad[0]][0]}; remove the row or "
            "fill it with a measured number"
        )
    lim, unit = limits[key]
    big = np.flatnonzero(np.abs(v) > lim)
    if big.size:
        raise InputError(
            f"data file {name!r}: column {hname} has the value {cells[big[0]][:20]} "
            f"at line {body[big[0]][0]}, beyond the accepted |{key}| <= {lim:g} "
            f"{unit}; check the column and its units (SI)"
        )
    return v
