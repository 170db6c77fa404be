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
