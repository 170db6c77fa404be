"""Regenerate the README's option table from the registry:
``python -m petsc_ssi.app.docs [README.md]`` rewrites the text between the
markers ``<!-- options:begin -->`` and ``<!-- options:end -->``."""
import sys

BEGIN, END = "<!-- options:begin -->", "<!-- options:end -->"


def table():
    from .. import options
    from . import kinds, estimate, impedance, record  # noqa: F401  (every option declared)
    return options.markdown_table()


def update(path="README.md"):
    text = open(path).read()
    i, j = text.index(BEGIN) + len(BEGIN), text.index(END)
    new = text[:i] + "\n" + table() + "\n" + text[j:]
    if new != text:
        open(path, "w").write(new)
    return new != text


if __name__ == "__main__":
    changed = update(sys.argv[1] if len(sys.argv) > 1 else "README.md")
    print("README option table", "updated" if changed else "already current")
