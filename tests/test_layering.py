"""The package stays layered (issue 26): no import cycle among its modules, and no library module
imports the application layer (``petsc_ssi.app``).

Every import counts, as a reader meets it: at module level and inside functions, relative or
absolute, ``from X import name`` where ``name`` is a module, and ``importlib.import_module`` /
``__import__`` with a literal name. An import of a package's own ``__init__`` from inside it is
not an edge (Python runs the package first either way). The checks parse the sources only
(nothing is imported), so they run in a fraction of a second.
"""
import ast
import os

import pytest

pytestmark = pytest.mark.unit

ROOT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "petsc_ssi")
APP = "petsc_ssi.app"
ENTRY = "petsc_ssi.__main__"          # `python -m petsc_ssi`: the application's entry point


def modules(root=ROOT):
    """{dotted module name: path} of every .py file of the package."""
    out = {}
    for d, _, files in os.walk(root):
        for f in files:
            if f.endswith(".py"):
                p = os.path.join(d, f)
                rel = os.path.relpath(p, os.path.dirname(root))[:-3].replace(os.sep, ".")
                out[rel[:-9] if rel.endswith(".__init__") else rel] = p
    return out


def _resolve(name, known):
    while name and name not in known:
        name = name.rpartition(".")[0]
    return name or None


def imports(path, mod, known):
    """[(target module, line)] of every import in ``path`` that names a module of the package."""
    tree = ast.parse(open(path, encoding="utf-8").read(), path)
    base = mod if path.endswith("__init__.py") else mod.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = base.split(".")
                prefix = ".".join(parts[: len(parts) - (node.level - 1)])
                src = prefix + ("." + node.module if node.module else "")
            else:
                src = node.module or ""
            names = [src + "." + a.name if (src + "." + a.name) in known else src for a in node.names]
        elif isinstance(node, ast.Call):
            f = node.func
            fname = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
            if fname in ("import_module", "__import__") and node.args and \
                    isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str):
                name = node.args[0].value
                if name.startswith("."):
                    name = base + name if not name.startswith("..") else base.rpartition(".")[0] + name[1:]
                names = [name]
        for n in names:
            t = _resolve(n, known)
            if t:
                out.append((t, node.lineno))
    return out


def graph(root=ROOT):
    mods = modules(root)
    known = set(mods)
    g, where = {m: set() for m in mods}, {}
    for m, p in mods.items():
        for t, line in imports(p, m, known):
            if t == m or m.startswith(t + "."):          # a module's own package __init__: not an edge
                continue
            g[m].add(t)
            where.setdefault((m, t), f"{os.path.relpath(p, os.path.dirname(ROOT))}:{line}")
    return g, where


def cycles(g):
    """Strongly connected components with more than one module (Tarjan, iterative)."""
    index, low, on, stack, comps, counter = {}, {}, set(), [], [], [0]
    for root in sorted(g):
        if root in index:
            continue
        work = [(root, iter(sorted(g[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(g[w]))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        comps.append(sorted(comp))
    return comps


def test_no_import_cycle():
    g, where = graph()
    found = cycles(g)
    lines = []
    for comp in found:
        lines.append(f"cycle of {len(comp)} modules:")
        lines += [f"  {a} -> {b} ({where[(a, b)]})" for a in comp for b in sorted(g[a]) if b in comp]
    assert not found, "\n".join(lines)


def test_library_does_not_import_the_application():
    g, where = graph()
    bad = [f"{m} -> {t} ({where[(m, t)]})" for m in sorted(g) if not (m in (APP, ENTRY) or m.startswith(APP + "."))
           for t in sorted(g[m]) if t == APP or t.startswith(APP + ".")]
    assert not bad, "library modules import the application layer:\n" + "\n".join(bad)


# Leaves: modules that promise, in their docstrings, to stand alone (numpy/scipy/numba only), so that
# they can be tested and reused alone: they import no module of the package but other leaves.
LEAVES = ("petsc_ssi.analytic.free_field", "petsc_ssi.analytic.pekeris", "petsc_ssi.analytic.impedance_refs",
          "petsc_ssi.seismic.records", "petsc_ssi.seismic.response_spectrum", "petsc_ssi.spectrum",
          "petsc_ssi.timegrid", "petsc_ssi.sysmem", "petsc_ssi.mesh.quad9", "petsc_ssi.bem.kernels",
          "petsc_ssi.bem.simd", "petsc_ssi.bem.patterns", "petsc_ssi.bem.packs", "petsc_ssi.bem.windows",
          "petsc_ssi.bem.stability_map",
          "petsc_ssi.fem.elements.base", "petsc_ssi.coupling.contact")
# Folders: io/ holds files, formats and the recorder; the observers of a domain live beside it
# (issue 40), so io/ imports none of the domains' packages (the seismic input's leaves, the record
# readers, it may: a checkpoint's key names a record's format).
FOLDER_RULES = {"petsc_ssi.io": ("petsc_ssi.bem", "petsc_ssi.fem", "petsc_ssi.coupling", "petsc_ssi.seismic.input",
                                 "petsc_ssi.seismic.options")}


def folder_violations(g, where, leaves=LEAVES, rules=FOLDER_RULES):
    bad = [f"leaf {m} imports {t} ({where[(m, t)]})" for m in leaves if m in g for t in sorted(g[m])
           if t not in leaves]
    for folder, banned in rules.items():
        for m in sorted(g):
            if m == folder or m.startswith(folder + "."):
                bad += [f"{m} -> {t} ({where[(m, t)]})" for t in sorted(g[m])
                        if any(t == b or t.startswith(b + ".") for b in banned)]
    return bad


def test_leaves_and_folders_keep_their_rules():
    g, where = graph()
    assert all(m in g for m in LEAVES), [m for m in LEAVES if m not in g]
    bad = folder_violations(g, where)
    assert not bad, "\n".join(bad)


def test_the_checks_can_fail(tmp_path):
    """The same checks on a small package with a cycle inside a function and an importlib load,
    and a library module importing its app: both are found."""
    pkg = tmp_path / "petsc_ssi"
    (pkg / "app").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "app" / "__init__.py").write_text("")
    (pkg / "app" / "cli.py").write_text("from ..a import f\n")
    (pkg / "a.py").write_text("def f():\n    from . import b\n")
    (pkg / "b.py").write_text("import importlib\nimportlib.import_module('petsc_ssi.a')\n")
    (pkg / "c.py").write_text("from .app import cli\n")
    g, _ = graph(str(pkg))
    assert cycles(g) == [["petsc_ssi.a", "petsc_ssi.b"]]
    (pkg / "io").mkdir()
    (pkg / "io" / "__init__.py").write_text("")
    (pkg / "io" / "rec.py").write_text("def f():\n    from ..bem import x\n")
    (pkg / "bem").mkdir()
    (pkg / "bem" / "__init__.py").write_text("")
    (pkg / "bem" / "x.py").write_text("")
    (pkg / "leaf.py").write_text("from .a import f\nfrom . import leaf2\n")
    (pkg / "leaf2.py").write_text("")
    g, where = graph(str(pkg))
    bad = folder_violations(g, where, leaves=("petsc_ssi.leaf", "petsc_ssi.leaf2"))
    assert len(bad) == 2 and "leaf petsc_ssi.leaf imports petsc_ssi.a" in bad[0] and "petsc_ssi.io.rec ->" in bad[1]
    assert "petsc_ssi.app.cli" in g["petsc_ssi.c"]
