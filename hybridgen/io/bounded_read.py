"""Reading small text inputs (pose files, label CSVs) with a size limit and a clear encoding rule.

A path that names ``/dev/zero``, a FIFO that never ends or a multi-gigabyte file by mistake costs at most
``limit`` bytes and gives one line instead of exhausting memory. Text is UTF-8 (a byte order mark is
dropped); with ``latin1_fallback`` a file that is not valid UTF-8 is read as Latin-1 (every byte is a
character there, so nothing fails; the names look as a Latin-1 editor shows them), otherwise it is an
error naming the first offending byte.
"""
from __future__ import annotations

from pathlib import Path

from ..input_paths import not_found
from ..errors import InputError

MAX_POSE_FILE_BYTES = 64 * 2**20
MAX_TABLE_BYTES = 16 * 2**20


def read_bounded_text(path: str | Path, limit: int, what: str, *, latin1_fallback: bool = False) -> str:
    """The text of ``path`` (at most ``limit`` bytes), decoded as described in the module documentation."""
    try:
        with open(path, "rb") as handle:
            data = handle.read(limit + 1)
    except FileNotFoundError:
        raise InputError(not_found(what, path)) from None  # names both places a config run looked
    except OSError as exc:
        raise InputError(f"cannot read {what} '{path}': {exc.strerror or exc}") from None
    if len(data) > limit:
        raise InputError(f"{what} '{path}' is larger than {limit // 2**20} MiB; refusing to read it")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        if latin1_fallback:
            return data.decode("latin-1")
        raise InputError(f"{what} '{path}' is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset "
                         f"{exc.start}); save it as UTF-8") from None
