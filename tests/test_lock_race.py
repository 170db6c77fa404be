"""The output lock of two runs started at once (petsc_ssi/io/lock.py): a lock is made whole (written to a
file of the run's own, then hard-linked to the lock's name), so a second run never finds it empty; a lock
found empty (made with O_EXCL where there are no hard links, and written right after) is read again before it
counts as foreign: the second run is told that another run writes the file, not that the lock is not ours."""
import os
import threading
import time

import pytest

pytestmark = pytest.mark.unit


def test_a_made_lock_is_whole_and_leaves_no_temporary(tmp_path):
    from petsc_ssi.io import lock
    f = str(tmp_path / "o.h5.lock")
    lock._make(f, "host h\npid 12345\nstarted now\n")
    assert open(f).read() == "host h\npid 12345\nstarted now\n"
    assert os.listdir(tmp_path) == ["o.h5.lock"]
    with pytest.raises(FileExistsError):
        lock._make(f, "host h\npid 1\n")
    assert os.listdir(tmp_path) == ["o.h5.lock"] and "12345" in open(f).read()


def test_a_lock_found_empty_is_read_again(tmp_path):
    """An empty lock whose owner writes it 0.2 s later: the second run waits for its text and refuses with
    'being written by another run' (the live owner: this process's parent)."""
    from petsc_ssi.io import lock
    f = str(tmp_path / "o.h5.lock")
    open(f, "w").close()

    def write():
        time.sleep(0.2)
        with open(f, "w") as fh:
            fh.write(f"host {__import__('platform').node()}\npid {os.getppid()}\nstarted then\n")
    th = threading.Thread(target=write)
    th.start()
    err, note = lock._create(f, None)
    th.join()
    assert err is not None and "is being written by another run" in err, err
    assert f"pid {os.getppid()}" in err


def test_a_lock_that_stays_empty_is_foreign(tmp_path, monkeypatch):
    from petsc_ssi.io import lock
    monkeypatch.setattr(lock, "EMPTY_WAIT", 0.01)
    f = str(tmp_path / "o.h5.lock")
    open(f, "w").close()
    err, _ = lock._create(f, None)
    assert "exists and is not a petsc-ssi lock" in err
