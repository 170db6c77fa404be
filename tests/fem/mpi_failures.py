"""Run under mpirun -n 2 by test_fem_parallel.py: make ONE rank fail with an exception that is not
an SSIError inside each rank-0-only or local step, and print what every rank raised.

Cases: load_mesh (rank 0 builds the mesh), assemble (rank 1's local stiffness), Output() (rank 0
creates the directory), Output.close() (rank 0 writes the serial data). Each rank writes lines
'case: SSIError: message' (or 'case: no error') to WORKDIR/rank<r>.txt; a hang is the test's timeout.
"""
import os
import sys
from types import SimpleNamespace


def raising(exc):
    def f(*args, **kw):
        raise exc
    return f


def main(workdir):
    from petsc_ssi.petsc import init, SSIError
    PETSc = init([sys.argv[0]])
    comm = PETSc.COMM_WORLD
    rank = comm.getRank()
    from petsc_ssi.fem import mesh as fmesh, assembly
    from petsc_ssi.fem.dofmap import BrickDofMap
    from petsc_ssi.io import output
    cfg = SimpleNamespace(fem_mesh="box", fem_box_cells="2,2,2", fem_box_size="1,1,0.5",
                          fem_box_origin="-0.5,-0.5,0", fem_renumber=True)
    mesh = fmesh.structured_box((2, 2, 2))
    layout = BrickDofMap(mesh.n_nodes, comm)
    mat = assembly.Material(1e6, 0.25, 1e3)
    blocker = os.path.join(workdir, "a_file")
    if rank == 0:
        open(blocker, "w").close()
    comm.tompi4py().Barrier()

    def case_mesh():
        if rank == 0:
            fmesh.build_mesh = raising(ValueError("boom on rank 0\nsecond line"))
        fmesh.load_mesh(cfg, comm)

    def case_assemble():
        if rank == 1:
            assembly.local_stiffness_csr = raising(MemoryError("no memory on rank 1"))
        assembly.assemble(mesh, mat, layout)

    def case_output_dir():
        output.Output(os.path.join(blocker, "sub", "out.h5"), comm)     # a file where a directory must be

    def case_output_close():
        out = output.Output(os.path.join(workdir, "out.h5"), comm)
        out.write_mesh(layout.nodal_vec(mesh.coords), mesh.cells if rank == 0 else None, "hex8")
        if rank == 0:
            out._write_xdmf = raising(OSError("disk full"))
        out.close()

    lines = []
    for name, case in (("load_mesh", case_mesh), ("assemble", case_assemble),
                       ("output_dir", case_output_dir), ("output_close", case_output_close)):
        try:
            case()
            msg = "no error"
        except SSIError as exc:
            msg = f"SSIError: {exc}"
        lines.append(f"{name}: {msg}")
    with open(os.path.join(workdir, f"rank{rank}.txt"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    comm.tompi4py().Barrier()


if __name__ == "__main__":
    main(sys.argv[1])
