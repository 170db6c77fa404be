"""Parsers of point lists and number triples given as option strings (FEM and BEM)."""
import numpy as np

from .petsc import SSIError


def parse_points(text, ncols=3, what="-ssi_receivers", fields="x,y,z"):
    """'x,y,z;x,y,z' -> (R, ncols) float array ((0, ncols) if empty).

    Rows are separated by ';' or newlines. SSIError naming the first
    malformed row: '<what>: '<row>' is not <ncols> comma-separated numbers
    (each point needs <fields>)'.
    """
    rows = [r.strip() for r in str(text or "").replace("\n", ";").split(";") if r.strip()]
    out = []
    for r in rows:
        try:
            vals = [float(s) for s in r.split(",")]
        except ValueError:
            vals = []
        if len(vals) != ncols or not np.all(np.isfinite(vals)):
            raise SSIError(f"{what}: '{r}' is not {ncols} comma-separated numbers (each point needs {fields})")
        out.append(vals)
    return np.array(out, dtype=float).reshape(-1, ncols)


def parse_triple(text, kind=float, what="value"):
    """'a,b,c' -> a tuple of three ``kind``; SSIError otherwise."""
    try:
        vals = tuple(kind(s) for s in str(text).split(","))
    except ValueError:
        vals = ()
    if len(vals) != 3:
        raise SSIError(f"{what} '{text}': must be three comma-separated numbers")
    return vals
