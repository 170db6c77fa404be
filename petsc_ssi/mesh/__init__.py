"""Meshes: nine-node quadrilateral surfaces (BEM) and their readers."""
