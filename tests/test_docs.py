"""The README's option table is generated from the registry and current."""
import os

from helpers import ROOT
import pytest

pytestmark = pytest.mark.run


def test_readme_option_table_is_current():
    from petsc_ssi.app.docs import table, BEGIN, END
    text = open(os.path.join(ROOT, "README.md")).read()
    i, j = text.index(BEGIN) + len(BEGIN), text.index(END)
    assert text[i:j].strip() == table().strip(), "run: python -m petsc_ssi.app.docs"
