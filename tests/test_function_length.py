"""No function of the BEM kernels' package over 80 lines (issue 40, item 5): a function that long
(``assemble_rows`` grew to 164 lines and 19 parameters) is split into named steps. Counted as
``end_lineno - lineno + 1`` of every function and method (nested ones too) of ``petsc_ssi/bem``,
from the ``def`` line to the last (decorators not counted, the docstring counted); the sources are
parsed, not imported."""
import ast
import os

import pytest

pytestmark = pytest.mark.unit

BEM = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "petsc_ssi", "bem")
MAX_LINES = 80


def long_functions(folder=BEM, limit=MAX_LINES):
    """[(file, function, first line, lines)] of the functions of ``folder``'s modules over ``limit`` lines."""
    out = []
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".py"):
            continue
        with open(os.path.join(folder, name)) as fh:
            tree = ast.parse(fh.read(), name)
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > limit:
                    out.append((name, node.name, node.lineno, n))
    return out


def test_no_function_in_bem_over_80_lines():
    assert long_functions() == [], "split these into named steps: " + ", ".join(
        f"{f}:{line} {fn} ({n} lines)" for f, fn, line, n in long_functions())


def test_the_count_sees_a_long_function(tmp_path):
    """The check counts what it should: a 81-line function is found, an 80-line one is not."""
    body = "\n".join(f"    x{i} = {i}" for i in range(79))
    (tmp_path / "m.py").write_text(f"def long():\n{body}\n    return 0\n\n\ndef short():\n{body}\n")
    assert long_functions(str(tmp_path)) == [("m.py", "long", 1, 81)]
