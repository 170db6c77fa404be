"""The one-storey test building of the coupled tests (test_building_ci.py, test_ssi_frequency.py):
a foundation slab of n x n shells on [-B, B]^2 at z = 0 (its nodes are soil nodes), four corner
columns of nz frames and a roof slab of n x n shells at z = H, written with petsc-ssi's .msh writer."""
import numpy as np


def one_storey_msh(path, n, B=1.0, H=1.5, nz=3, half=False, roof=True):
    """Groups foundation, roof, columns and the point A (roof centre, on y = 0); ``half`` keeps
    y >= 0 (the columns at y = B); ``roof=False``: the foundation slab alone."""
    from helpers import petsc
    petsc()                                  # PETSc before gmsh
    from petsc_ssi.mesh.gmsh import write_msh
    x = np.linspace(-B, B, n + 1)
    y = x[x >= -1e-12 * B] if half else x
    nodes = []

    def slab(z):
        X, Y = np.meshgrid(x, y, indexing="ij")
        base = len(nodes)
        nodes.extend(np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, z)]).tolist())
        idx = base + np.arange(X.size).reshape(X.shape)
        return np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4), idx

    fcells, fidx = slab(0.0)
    groups = {"foundation": ("quad4", fcells)}
    if roof:
        rcells, ridx = slab(H)
        cols = []
        for i in (0, n):
            for j in ((len(y) - 1,) if half else (0, len(y) - 1)):
                chain = [int(fidx[i, j])]
                for k in range(1, nz):
                    nodes.append([x[i], y[j], H * k / nz])
                    chain.append(len(nodes) - 1)
                chain.append(int(ridx[i, j]))
                cols += [[a, b] for a, b in zip(chain[:-1], chain[1:])]
        groups.update(roof=("quad4", rcells), columns=("line2", cols),
                      A=("point", [[int(ridx[n // 2, 0 if half else n // 2])]]))
    write_msh(path, np.array(nodes, float), groups)
    return path
