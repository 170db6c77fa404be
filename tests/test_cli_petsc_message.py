"""The one line of a PETSc error (app/cli.py ``_petsc_message``) reads PETSc's own messages on this
petsc4py and on newer ones: 3.18 keeps the last error's entries in one class-wide list
(``Error._traceback_``), newer petsc4py on each error (``_traceback``), where the class-wide list, if
any, may be an older error's and must not be read."""
import pytest

from helpers import petsc

pytestmark = pytest.mark.unit


def _message(exc):
    from petsc_ssi.app.cli import _petsc_message
    return _petsc_message(exc)


def test_a_real_petsc_error_gives_petscs_message():
    PETSc = petsc()
    v, w = PETSc.Vec().createSeq(3), PETSc.Vec().createSeq(4)
    with pytest.raises(PETSc.Error) as info:
        v.axpy(1.0, w)                  # lengths 3 and 4
    msg = _message(info.value)
    assert msg.startswith(" at VecAXPY(): ") and "global size 4 != parameter # 1 global size 3" in msg, msg


def test_the_errors_own_entries_win_over_a_class_wide_list():
    class Old(Exception):
        _traceback_ = ["MatLUFactor() at matrix.c:3000", "Zero pivot in LU factorization"]

    class New(Old):
        def __init__(self, entries):
            super().__init__()
            self._traceback = entries

    assert _message(Old()) == " at MatLUFactor(): Zero pivot in LU factorization"
    assert _message(New(["KSPSolve() at itfunc.c:800", "Diverged"])) == " at KSPSolve(): Diverged"
    assert _message(New([])) == ""      # its own list empty: the class-wide one is another error's
