"""FEM-BEM coupling with bonded or unilateral (Kuhn-Tucker) contact (paper Section 4)."""
