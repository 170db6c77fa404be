"""sysmem.release_freed (issue 29): memory freed into glibc's heap is given back to the system.
The BEM assembly calls it after the shared element cache's integration, whose temporaries and
messages otherwise stayed resident through the rest of the assembly (paper case: 0.35 GB a rank,
jobscripts/assembly_memory.py;
the peak over the node 5.07 -> 4.40 GB with -ssi_lag_single_from 3, 7.78 -> 7.10 GB in double)."""
import numpy as np
import pytest

from petsc_ssi.sysmem import process_rss, release_freed

pytestmark = pytest.mark.unit


def test_freed_heap_memory_is_given_back():
    """3000 arrays of 100 kB (below glibc's mmap threshold: from the heap, touched), all freed but
    the last (which pins the heap's top, so glibc's automatic trim at free cannot give the rest
    back): resident memory falls by at least 200 of their 300 MB when release_freed is called."""
    a = [np.ones(12800) for _ in range(3000)]
    keep = a[-1]
    a = None
    before = process_rss()
    if not release_freed():
        pytest.skip("no malloc_trim in this C library")
    after = process_rss()
    assert keep[0] == 1.0
    assert before - after >= 200e6, (before, after)


def _vm_flags(addr):
    """VmFlags of the mapping of this process that holds address ``addr`` (/proc/self/smaps)."""
    cur = None
    with open("/proc/self/smaps") as fh:
        for line in fh:
            head = line.split()[0]
            if "-" in head and not head.endswith(":"):
                lo, hi = (int(x, 16) for x in head.split("-"))
                cur = lo <= addr < hi
            elif cur and line.startswith("VmFlags:"):
                return line.split()[1:]
    return None


def test_a_lag_arrays_tail_gets_small_pages():
    """sysmem.small_pages_from (the lag arrays' pages past 85 % of the estimate, issue 29): on a
    32 MB array, the kernel marks the mapping from 16 MB (rounded up to a page) to the end
    'nh' (no huge pages) and leaves its first half as it was; an empty range is refused."""
    import sys
    import os
    if not sys.platform.startswith("linux") or not os.path.isdir("/sys/kernel/mm/transparent_hugepage"):
        pytest.skip("no transparent huge pages (Linux's madvise flags in /proc/self/smaps)")
    from petsc_ssi.sysmem import small_pages_from
    a = np.empty(4 << 20)                                   # 32 MB: its own mapping
    assert small_pages_from(a, 16 << 20)
    head, tail = a.ctypes.data + 4096, a.ctypes.data + (24 << 20)
    assert "nh" in _vm_flags(tail), _vm_flags(tail)
    assert "nh" not in _vm_flags(head), _vm_flags(head)
    assert not small_pages_from(a, a.nbytes)               # nothing past the end
    a[:] = 1.0                                              # the array is written as before
    assert float(a.sum()) == float(a.size)


def test_small_lag_buckets_have_small_pages_throughout():
    """Buckets(small=True) (-ssi_huge_pages auto on a VM that reports free pages, or off): every lag
    array of 2 MB and more is marked 'nh' from its first page to its last; without it, a lag array's
    head keeps numpy's advice and only its tail past SMALL_FROM of the expected blocks is small."""
    import sys
    import os
    if not sys.platform.startswith("linux") or not os.path.isdir("/sys/kernel/mm/transparent_hugepage"):
        pytest.skip("no transparent huge pages (Linux's madvise flags in /proc/self/smaps)")
    from petsc_ssi.bem.lagset import Buckets
    from petsc_ssi.bem.assemble import get_lag
    n = 1 << 20                                             # blocks a lag: 4 MB of columns, 32 MB of values
    for small in (True, False):
        B = Buckets(2, np.arange(4), 4, capacity=[n, n], m=4, expected=[n, n], small=small)
        for lag in (1, 2):
            c, v, _ = get_lag(B._c, B._v, B._v32, lag)
            for a in (c, v):
                head, tail = a.ctypes.data + 4096, a.ctypes.data + a.nbytes - 4096
                assert "nh" in _vm_flags(tail), (small, lag, _vm_flags(tail))
                assert ("nh" in _vm_flags(head)) is small, (small, lag, _vm_flags(head))
