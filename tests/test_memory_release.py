"""sysmem.release_freed (issue 29): memory freed into glibc's heap is given back to the system.
The BEM assembly calls it after the shared element cache's integration, whose temporaries and
messages otherwise stayed resident through the rest of the assembly (paper case: 0.35 GB a rank,
jobscripts/assembly_memory.py;
the peak over the node 5.07 -> 4.40 GB with -ssi_lag_single_from 3, 7.78 -> 7.10 GB in double)."""
import numpy as np
import pytest

from petsc_ssi.sysmem import process_rss, release_freed


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
