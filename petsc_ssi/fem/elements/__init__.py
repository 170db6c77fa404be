"""Element registry of the structural FE: name -> element type (see base.py).

Each element lives in its own module (``hex8.py``, ``frame.py``, ``shell.py``) with a
header stating its formulation and sources, and registers itself on import
(bempp-cl's kernel dispatch)."""
import importlib

from .base import ElementType, Props  # noqa: F401

NAMES = ("hex8", "frame", "shell")
REGISTRY = {}


def register(elem):
    REGISTRY[elem.name] = elem
    return elem


def get(name):
    """The element type ``name`` (KeyError if unknown)."""
    if name not in REGISTRY:
        if name not in NAMES:
            raise KeyError(name)
        importlib.import_module(f".{name}", __package__)
    return REGISTRY[name]
