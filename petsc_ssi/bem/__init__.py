"""Time-domain BEM for the elastic half-space (paper Section 2)."""
