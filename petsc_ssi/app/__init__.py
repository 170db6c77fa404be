"""The application layer: the command line, the table of problem kinds and the commands.

Nothing in the library (``petsc_ssi.*`` outside ``app``) imports this package
(``tests/test_layering.py``).
"""
