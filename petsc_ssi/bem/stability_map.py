"""What the stability map of runs/stability found, as numbers the runs warn from (a leaf module:
bem/halfspace.py and bem/stability.py both use it)."""

# What the stability map of runs/stability (stability_map.csv, README "Results: stability map")
# found, in beta_s = c_s dt / l (l: node spacing): per scheme, the smallest beta from which every
# mapped run (h = 0.5, 1, 1.5 m) was stable, and the largest beta mapped (every run stable there).
# tests/bem/test_beta_warning.py checks these against the CSV.
MAP_STABLE_FROM = {"plain": 0.15, "stabilized": 0.07}
MAP_BETA_MAX = 2.0


def beta_warning(scheme, beta_lo, beta_hi):
    """One line when beta_s = c_s dt / l over the mesh ([beta_lo, beta_hi]: the largest and the
    smallest node spacing) leaves what the stability map found stable for ``scheme``, else None."""
    lo = MAP_STABLE_FROM.get(scheme)
    tips = []
    if lo is not None and beta_lo < lo:
        other = [f"-ssi_scheme {k} from {v:g}" for k, v in MAP_STABLE_FROM.items() if k != scheme and v < lo]
        tips.append(f"below {lo:g}, from which every {scheme} run of the stability map was stable (the "
                    "largest elements need a larger dt" + (f", or {other[0]}" if other else "") + ")")
    if beta_hi > MAP_BETA_MAX * (1 + 1e-9):
        tips.append(f"above {MAP_BETA_MAX:g}, the largest the stability map ran (the smallest elements are "
                    "crossed in less than a step: a smaller dt or coarser elements there)")
    if not tips:
        return None
    return (f"beta_s = c_s dt / l spans [{beta_lo:.3g}, {beta_hi:.3g}] (largest to smallest node spacing), "
            + " and ".join(tips) + ": the marching may be unstable (runs/stability/README.md; "
            "-ssi_check_stability tests this mesh's beta)")
