"""This process declines transparent huge pages before Dr.Jit's LLVM backend allocates its wavefronts.

Dr.Jit rounds every allocation up to a power of two and asks Linux for transparent huge pages
(``madvise(MADV_HUGEPAGE)``) on those of 2 MiB and more. The kernel then zeroes a whole 2 MiB page on the first touch
of any byte of it, including the unused tail of each rounded-up buffer. With 4 KiB pages only the pages a kernel
writes are zeroed. Measured on BlenderProc's ``basics/basic`` (2 frames at 512 x 512, this 2-core machine): with
huge pages, 4.6 % of the whole process's CPU was ``clear_page_erms`` under ``do_huge_pmd_anonymous_page``
(~480 MB of huge pages faulted); declined, the whole process took 8.52 s instead of 8.82 s (3 alternating pairs,
each pair the same way round). Colors are the same bytes either way: only the page size changes.

``prctl(PR_SET_THP_DISABLE)`` applies to this process and the processes it starts. Elsewhere than on Linux, or
with ``$HYBRIDGEN_HUGE_PAGES=1``, nothing changes.
"""
from __future__ import annotations

import ctypes
import os
import sys

PR_SET_THP_DISABLE = 41
"""``linux/prctl.h``: with argument 1, no transparent huge pages for this process (inherited by its children)."""
KEEP_ENV = "HYBRIDGEN_HUGE_PAGES"
"""Set to 1 to keep transparent huge pages."""

_declined = False


def decline_huge_pages() -> bool:
    """Asks Linux for 4 KiB pages only in this process (once); True if it now has them."""
    global _declined
    if _declined:
        return True
    if not sys.platform.startswith("linux") or os.environ.get(KEEP_ENV) == "1":
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        _declined = libc.prctl(PR_SET_THP_DISABLE, 1, 0, 0, 0) == 0
    except (OSError, AttributeError):
        _declined = False
    return _declined
