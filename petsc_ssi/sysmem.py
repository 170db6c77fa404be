"""Memory of the machine and of this process, from /proc and the cgroup (Linux; leaf module).

``machine_memory``   bytes this process may use: MemTotal, or its cgroup's limit when lower
``process_rss``      resident memory now; ``proc_status_bytes`` any field of /proc/self/status
``peak_rss``         collective: (largest, summed) peak resident memory of the ranks so far
``small_pages_from`` small pages for part of an array; ``free_page_reporting`` a VM handing memory back
"""
import mmap
import os


def _cgroup_limit(proc="/proc/self/cgroup", root="/sys/fs/cgroup"):
    """The memory limit of this process's cgroup (v2 memory.max, or v1 memory.limit_in_bytes), in
    bytes, or inf: a batch job or container may have less than the machine."""
    paths = []
    try:
        with open(proc) as fh:
            for line in fh:
                parts = line.strip().split(":", 2)
                if len(parts) == 3 and (parts[1] == "" or "memory" in parts[1].split(",")):
                    rel = parts[2].lstrip("/")
                    if parts[1] == "":
                        paths += [os.path.join(root, rel, "memory.max"), os.path.join(root, "memory.max")]
                    else:
                        paths += [os.path.join(root, "memory", rel, "memory.limit_in_bytes"),
                                  os.path.join(root, "memory", "memory.limit_in_bytes")]
    except OSError:
        pass
    best = float("inf")
    for p in paths:
        try:
            with open(p) as fh:
                v = fh.read().strip()
        except OSError:
            continue
        if v and v != "max":
            try:
                best = min(best, float(v))
            except ValueError:
                pass
    return best if best < 2 ** 60 else float("inf")      # cgroup v1 writes ~2^63 for "no limit"


def machine_memory():
    """Bytes of memory this process may use: the machine's (MemTotal), or its cgroup's limit when
    that is lower (``_cgroup_limit``)."""
    total = float("inf")
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemTotal"):
                    total = float(line.split()[1]) * 1024
                    break
    except OSError:
        pass
    return min(total, _cgroup_limit())


def proc_status_bytes(field):
    """A memory field of /proc/self/status ('VmRSS', 'VmHWM'), bytes; None where /proc is missing."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(field + ":"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return None


def process_rss():
    """This process's resident memory now (bytes; 0 where /proc is missing)."""
    return proc_status_bytes("VmRSS") or 0.0


def _hwm():
    """This process's peak resident memory, bytes: VmHWM of /proc/self/status (the peak of this
    program alone; getrusage's ru_maxrss also keeps the RSS of the process it was forked from, e.g.
    a large pytest), else ru_maxrss."""
    hwm = proc_status_bytes("VmHWM")
    if hwm is not None:
        return hwm
    import resource
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024.0      # Linux: kB


def peak_rss(comm):
    """Collective: (largest, summed) peak resident memory of the ranks so far, bytes (Linux)."""
    from mpi4py import MPI
    hwm = _hwm()
    mpi = comm.tompi4py()
    return mpi.allreduce(hwm, op=MPI.MAX), mpi.allreduce(hwm)


_LIBC = {}


def _libc(name, argtypes, restype):
    """The C library's function ``name`` through ctypes (errno kept), typed; None where this C library
    or platform has none. Looked up once per process."""
    if name not in _LIBC:
        fn = None
        try:
            import ctypes
            import ctypes.util
            fn = getattr(ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True), name, None)
            if fn is not None:
                fn.argtypes, fn.restype = argtypes, restype
        except (OSError, AttributeError):
            fn = None
        _LIBC[name] = fn
    return _LIBC[name]


def release_freed():
    """Give the memory freed into the C heap back to the system (glibc's ``malloc_trim``); returns
    True when it was called. Large temporaries (the shared element cache's integrals and the
    messages that carry them, numba's arrays) are freed into glibc's heap, which keeps them resident
    once its dynamic mmap threshold has risen past their size: about 0.35 GB a rank on the paper's
    Lamb case (``jobscripts/assembly_memory.py``), held through the rest of the assembly and counted
    in its peak (issue 29). A no-op
    where the C library has no ``malloc_trim`` (musl, macOS)."""
    import ctypes
    fn = _libc("malloc_trim", [ctypes.c_size_t], ctypes.c_int)
    if fn is None:
        return False
    fn(0)
    return True


MADV_NOHUGEPAGE = 15            # Linux (include/uapi/asm-generic/mman-common.h)
_PAGE = mmap.PAGESIZE


def small_pages_from(a, nbytes):
    """Ask the kernel to back the bytes of array ``a`` from ``nbytes`` on (rounded up to a page) by
    small pages: madvise(MADV_NOHUGEPAGE). The lag arrays are allocated with headroom over the
    memory estimate's block count; where numpy advises huge pages, the 2 MB page holding the last
    block a lag actually stores is faulted in whole, about 1 MB of zeros per array on average
    (0.12-0.14 GB a rank on the paper's Lamb case, issue 29: jobscripts/lag_tail_pages.py). With
    small pages from a little before the estimate on, the array's end costs a small page instead.
    Returns True when the advice was taken; a no-op (False) where there is no madvise (not Linux)
    or the range is empty."""
    import ctypes
    import sys
    fn = _libc("madvise", [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int], ctypes.c_int) \
        if sys.platform.startswith("linux") else None
    if fn is None or a.nbytes == 0:
        return False
    start = a.ctypes.data + max(int(nbytes), 0)
    start = (start + _PAGE - 1) // _PAGE * _PAGE
    end = (a.ctypes.data + a.nbytes) // _PAGE * _PAGE
    if end <= start:
        return False
    return fn(start, end - start, MADV_NOHUGEPAGE) == 0


VIRTIO_ID_BALLOON = 5           # Linux include/uapi/linux/virtio_ids.h
VIRTIO_BALLOON_F_REPORTING = 5  # include/uapi/linux/virtio_balloon.h: free page reporting


def free_page_reporting(root="/sys/bus/virtio/devices"):
    """True where this machine is a virtual machine whose balloon reports free pages to its host
    (a virtio balloon that negotiated VIRTIO_BALLOON_F_REPORTING, read from sysfs: each device's
    ``features`` is a string of '0'/'1', bit i at position i). There the host takes back free blocks
    of 2 MB and more, and a first write to one faults in the host as well: a huge page's first write
    cost 0.9-2.3 s/GB on the development VM, a small page's 0.42-0.48 s/GB
    (jobscripts/first_touch_pair.py, first_touch_sizes.py). False on bare metal, elsewhere, and where
    sysfs cannot be read."""
    try:
        devices = os.listdir(root)
    except OSError:
        return False
    for d in devices:
        try:
            with open(os.path.join(root, d, "device")) as fh:
                if int(fh.read().strip(), 16) != VIRTIO_ID_BALLOON:
                    continue
            with open(os.path.join(root, d, "features")) as fh:
                bits = fh.read().strip()
        except (OSError, ValueError):
            continue
        if len(bits) > VIRTIO_BALLOON_F_REPORTING and bits[VIRTIO_BALLOON_F_REPORTING] == "1":
            return True
    return False
