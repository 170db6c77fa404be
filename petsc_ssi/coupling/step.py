r"""``-ssi_problem ssi``: the structure (FEM) on the half-space (BEM), staggered
(paper Section 4, Table 2), with a bonded or unilateral interface.

Set-up (A.1): every input check (both meshes, the interface matching, the
contact options, the memory estimate) before any assembly; then the FE
matrices with D factorised once, the BEM lag matrices with the step matrix
factorised once (every interface node closed), and the interface
capacitance Z = A^{-1} H_s E_I (``contact.py``).

Per step n (B), two time couplings (-ssi_coupling):
staggered (the paper's Table 2; structure by the Green's-function integrator)
  B.1 u_f^n = FEM predictor (eq. 13; independent of the forces of step n);
  B.2 gap check with u_b^{n-1}, compatibility u_b = u_f^n at closed nodes;
  B.3 BEM step: history sum, one solve with the factorised matrix -> bonded
      solution y; the open nodes' correction through the capacitance Z_OO;
  B.4 traction check (p_N <= p_C at closed nodes, no penetration at open
      ones); B.3-B.4 repeat until the status is stable (only the small
      interface algebra is repeated: y does not depend on the status);
  B.5 interface forces f_f = -M p_b (consistent, ``interface.py``) as the
      load at t_n: p^n (direct, the paper) or 1.5 p^n - 0.5 p^{n-1}
      (extrapolated; not across a status change);
  B.6 FE velocity (eq. 14).
  Conditionally stable: the soil's impedance acts explicitly on the
  interface nodes (diverges when rho c_p A dt / m exceeds about 2).
implicit (default; structure by the trapezoidal rule in midpoint form,
  fem/integrators.py MidpointIntegrator): the structure's predictor w (no
  interface force), the BEM solution q with zero interface displacement, then
  the interface system of contact.ImplicitSolve couples u_f = w + 2 C f,
  f = -M p, p = q - Z u_b on the interface (C = [D^{-1}]_II), with the same
  active-set loop. The BE traction (the mean over (t_{n-1}, t_n]) enters the
  structure as the mean force of that interval, so both sides exchange the same
  discrete work per step.

Outputs: the soil fields in -ssi_output (quad9), the structure's in
<stem>_structure.h5 (hex8), both with XDMF; the interface series (u_f, u_b,
p_b, gap, p_N, status, open count, iterations, force resultants of both
sides) in the group "interface" of -ssi_output.
"""
import time

import numpy as np
import scipy.sparse as sp

from ..petsc import init, printf, solve_columns
from ..monitor import event
from .interface import force_matrix, InterfaceOperator, interface_offsets
from .contact import Capacitance, ContactLaw, StaggeredSolve, ImplicitSolve

# a structure's mirrored interface column against the same column solved (``Coupler._fem_images_hold``), over its
# largest entry: two solutions of the same equations by the structure's LU, apart by its round-off
FEM_IMAGE_TOL = 1e-9
# the structure's D against the reflections (``columns.commutation_defect``): round-off of an assembly whose entries
# span translations and rotations, E = 30 GPa members and slabs: 4.62e-12 on the paper's building
# (`OUT=<dir> T_END=0.05 RUNS=uniform-72-area-exact bash jobscripts/building_uniform.sh`, its log line when this
# bound was 1e-12); a member, mass or support on one side only leaves orders of magnitude more
FEM_COMMUTE_TOL = 1e-10


def _all_solved(R, why):
    """One line: the structure's interface columns all solved (``Coupler.fem_columns``), and why; R's Mats
    destroyed. Returns None (false)."""
    printf(f"[ssi] interface columns: the structure's all solved ({why})")
    for o in R.values():
        o.destroy()
    return None


class StaggeredStep:
    """The paper's staggered step (Table 2): FEM predictor (Green's-function integrator), the BEM
    with every interface node closed at u_b = u_f, the active-set corrections through the
    capacitance Z_OO, and the soil's force handed to the structure as an impulse (B.5-B.6)."""
    integrator = "green"
    record_scheme = "green"          # the record reaches the structure as a prescribed impulse: checked

    def __init__(self, cp):
        self.cp = cp
        self.solver = StaggeredSolve(cp.law, Capacitance(cp.Z_II))

    def predict(self, f_ext):
        return self.cp.integ.predict()                              # B.1 (no load of step n)

    def known_interface_u(self, wI):
        return wI - self.cp.uffI                                    # B.2: u_b = u_f (all closed), scattered

    def interface(self, yI, wI):
        return self.cp.law.step(self.solver(yI, wI), wI)            # B.2-B.4 (active set)

    def correct_soil(self, x, res, wI):
        O = res["O"]
        if O.size:                                                  # x = y - Z[:, O] delta_O
            self.cp.subtract_Z(x, (res["ub"] - wI)[O], O)

    def finish(self, f_ext, fI, res):
        cp = self.cp
        cp.Top.spread(fI, cp.ff)                                    # f_f = T^T f_I
        cp.ff.pointwiseMult(cp.ff, cp.integ.mask)
        cp.integ.correct(f_ext, cp.ff)                              # B.5-B.6

    def factoriser(self):
        return self.solver.cap


class ImplicitStep:
    """The interface-implicit step: the structure's predictor w (trapezoidal rule in midpoint
    form, no interface force), the BEM solution q with zero interface displacement, then the
    interface system u_f = w + 2 C f, f = -M p, p = q - Z u_b with the active-set loop
    (contact.ImplicitSolve), C = T D^-1 T^T. Under a wave the interface unknowns are taken relative
    to the free field (s - u_ff, w - u_ff), the soil's own scattered-field unknowns; the contact law
    sees the same gap, and u_b, u_f come back as totals."""
    integrator = "midpoint"
    record_scheme = None             # the interface force is solved with the soil: no prescribed load

    def __init__(self, cp):
        self.cp = cp
        cp.DEloc, C, cp.DEmir = cp.fem_columns()
        if cp.DEmir is not None:        # the steps' products from the representatives' columns
            cp.DEloc = None
        self.solver = ImplicitSolve(cp.law, cp.Z_II, 2.0 * C, cp.M3, 1.0)   # midpoint: u = w + D^-1 (2 f)
        self.solver.lu(cp.law.closed)                                       # the bonded LU, now

    def predict(self, f_ext):
        return self.cp.integ.predict(f_ext)

    def known_interface_u(self, wI):
        return np.zeros_like(wI)                                    # q: the soil with u_sc,I = 0

    def interface(self, yI, wI):
        # relative to the free field (a seismic input): the unknown s - u_ff and w - u_ff, so that
        # p = q - Z (s - u_ff) is formed from the small scattered part, not as the difference of
        # totals (which loses the digits of p where the structure follows the free field); the
        # gap (u_b - u_f) . n_f is the same; u_b and u_f are handed back as totals
        uff = self.cp.uffI
        # the free field's traction t_ff on faces below the ground: the structure takes p + t_ff (r)
        r = self.cp.law.offset if self.cp.law.offset is not None else np.zeros_like(yI)
        res = self.cp.law.step(self.solver(yI, wI - uff, r), None)
        if uff.any():
            res["ub"], res["uf"] = res["ub"] + uff, res["uf"] + uff
        return res

    def correct_soil(self, x, res, wI):
        self.cp.subtract_Z(x, res["ub"] - self.cp.uffI)              # x = q - Z (u_b - u_ff)

    def finish(self, f_ext, fI, res):
        cp = self.cp
        cp.du.getArray()[:] = (cp.DEloc @ (2.0 * fI) if cp.DEmir is None           # D^{-1} (2 f_I), midpoint form
                               else cp.DEmir.product(2.0 * fI))
        cp.integ.complete(cp.du)
        res["uf_check"] = cp.Top.gather(cp.integ.u)

    def factoriser(self):
        return self.solver


STRATEGIES = {"staggered": StaggeredStep, "implicit": ImplicitStep}


class Coupler:
    """Collective: the interface maps between the FE and BE layouts (the interface operator T,
    a scatter of the soil's interface values), the interface matrices (Z = A^-1 H_s E_I, and
    C = T D^-1 T^T for the implicit step) and the contact law; ``step()`` advances both sides
    with the time-coupling strategy of -ssi_coupling (``StaggeredStep`` or ``ImplicitStep``),
    through the marcher's public coupling API (bem/march.py)."""

    def __init__(self, cfg, comm, prob, march, iface, integ, model):
        PETSc = init()
        self.PETSc, self.cfg, self.comm = PETSc, cfg, comm
        self.prob, self.march, self.iface, self.integ, self.model = prob, march, iface, integ, model
        self.mode = cfg.coupling
        nI = iface.n
        self.nI = nI
        self.dofs_be = (3 * iface.be_nodes[:, None] + np.arange(3)).ravel().astype(PETSc.IntType)
        self.dofs_fe = model.dofmap.translation_dofs(iface.fe_nodes).ravel().astype(PETSc.IntType)
        # the interface values on every rank (3 n_I numbers: the small replicated
        # interface system; the fields stay distributed): the soil's by a scatter,
        # the structure's through the interface operator T (translations, and the
        # rotations through the slab offset when -ssi_interface_offset)
        self.seq_y = PETSc.Vec().createSeq(3 * nI, comm=PETSc.COMM_SELF)
        self.sc_be = PETSc.Scatter().create(march.u_tmpl, PETSc.IS().createGeneral(self.dofs_be, comm=PETSc.COMM_SELF),
                                            self.seq_y, None)
        self.offsets = (interface_offsets(model.mesh, iface, cfg.fem_interface) if cfg.interface_offset
                        else np.zeros((nI, 3)))
        self.Top = InterfaceOperator(comm, iface, model.dofmap, self.offsets if cfg.interface_offset else None,
                                     fe_mesh=model.mesh)
        self.own_k, self.own_loc = _owned(self.dofs_be, march.u_tmpl)
        self.fown_k, self.fown_loc = _owned(self.dofs_fe, integ.u)
        self.zero = iface.zero.ravel()
        self.ff = integ.u.duplicate()
        self.du = integ.u.duplicate()
        ev = event("SSI_Capacitance")
        ev.begin()
        t0 = time.perf_counter()
        self.Zmir = None
        self.Zrows, self.Zloc = self._bem_columns()
        self.Z_II = self._gather_rows(self.Zloc, self.own_k, self._zpos(self.own_loc))
        if self.Zmir is not None:       # the steps' products from the representatives' columns: every column dropped
            self.Zloc = None
        self.preload = contact_preload(cfg, comm, model, iface)
        self.law = ContactLaw(iface.n_b, iface.zero, cfg.contact, cfg.contact_cohesion, cfg.contact_tol,
                              cfg.contact_max_iter, cfg.contact_open_traction, comm=comm.tompi4py(),
                              preload=self.preload, separation=cfg.contact_separation)
        ex = cfg.coupling_traction == "extrapolated"
        self.c_new, self.c_old = (1.5, 0.5) if ex else (1.0, 0.0)
        self.M3 = np.kron(iface.M.toarray(), np.eye(3))   # (dense: the interface LUs' set-up)
        self.Msp = iface.M.tocsr()                         # the steps' products M3 p = M p per component
        self.strategy = STRATEGIES[self.mode](self)
        self.t_capacitance = time.perf_counter() - t0
        ev.end()
        # forces: f_f = F p (FE layout); rows of FE DOFs a symmetry plane (or the
        # user) fixes are left out: their reaction is not a load on the structure
        self.F = force_matrix(comm, iface, integ.u, prob.regions.n_load, march.p_tmpl, model.dofmap,
                              skip=model.fixed)
        self.pI_prev = np.zeros(3 * nI)
        self.closed_prev = self.law.closed.copy()
        self.fixed_I = np.isin(self.dofs_fe, np.asarray(model.fixed, np.int64))
        self.weights, self.first_moments = _area_weights(prob.mesh, iface)
        # points where the interface forces act on the structure's side (the slab's underside
        # with the offset): moments of both sides are taken about the origin
        self.arm = iface.x + self.offsets
        self._kv_initial, self._r, self._dkv, self._t = (march.u_tmpl.duplicate() for _ in range(4))
        self.uffI = np.zeros(3 * nI)

    def destroy(self):
        """Collective: the PETSc objects the coupler made (its force matrix, vectors, scatter and interface
        operator, the mirror images' signed permutations), at the end of the run, on every rank in the same order (not left
        to the garbage collector, whose order the ranks need not share)."""
        for mz in (self.Zmir, getattr(self, "DEmir", None)):
            if mz is not None:
                mz.destroy()
        self.Zmir = self.DEmir = None
        self.Top.destroy()
        for o in (self.F, self.seq_y, self.sc_be, self.ff, self.du, self._kv_initial, self._r, self._dkv, self._t):
            o.destroy()

    def solver_cap(self):
        """The object that factorises per active set (n_factor, t_factor)."""
        return self.strategy.factoriser()

    def dense_bytes(self):
        """Bytes of the dense interface matrices this rank holds (Z's and D^-1 T^T's local rows,
        Z_II, M3, C), and H_s's sparse interface columns (HsI)."""
        n = 3 * self.nI
        b = (self.Zloc.nbytes if self.Zmir is None else self.Zmir.nbytes) + self.Z_II.nbytes + self.M3.nbytes
        H = self.HsI
        if H is not None:
            b += H.data.nbytes + H.indices.nbytes + H.indptr.nbytes
        if hasattr(self, "DEloc"):
            b += (self.DEloc.nbytes if self.DEloc is not None else self.DEmir.nbytes) + 8 * n * n
        return b

    def _gather_rows(self, loc, own_k, own_loc):
        """Collective: the interface rows of a local column block, on every rank."""
        rows = self.comm.tompi4py().allgather((own_k, loc[own_loc]))
        out = np.zeros((3 * self.nI, loc.shape[1]))
        for k, zr in rows:
            out[k] = zr
        return out

    def _bem_columns(self):
        """(rows, Z): Z[:, j] = A^{-1} H_s e_j for the interface DOFs, this rank's local rows ``rows``
        (None: every local row); 3 n_I right-hand sides, solved many at a time (``petsc.solve_columns``),
        on a region around the interface with its own LU where -ssi_interface_columns allows
        (``columns.region_columns``: A^-1 decays geometrically; its truncation residual checked), else
        with the step matrix's factors."""
        m = self.march
        cols = np.flatnonzero(~self.zero)
        unit = m.u_tmpl.duplicate()
        tmp = m.u_tmpl.duplicate()
        lut = -np.ones(3 * self.nI, np.int64)
        lut[self.own_k] = self.own_loc
        parts = {}                              # H_s's columns by chunk, kept sparse for the residual check

        def by_product(i, rhs):                 # H_s e_j by the lags' products (collective)
            j = cols[i]
            unit.set(0.0)
            if lut[j] >= 0:
                unit.getArray()[lut[j]] = 1.0
            m.mult_step_H(unit, rhs)

        def block(i0, i1):                      # H_s's columns read off its lags (None: multiply)
            blk = m.step_H_columns(self.dofs_be[cols[i0:i1]])
            parts[i0] = None if blk is None else sp.csc_matrix(blk)
            return blk

        def full_block(i0, i1):                 # the columns as local rows, always
            blk = block(i0, i1)
            if blk is None:
                blk = np.zeros((tmp.getLocalSize(), i1 - i0))
                for i in range(i0, i1):
                    by_product(i, tmp)
                    blk[:, i - i0] = tmp.getArray(readonly=True)
            return blk

        from .columns import region_columns
        rows = None
        with event("SSI_BEM_Solve"):
            got = region_columns(self.cfg, m, self.prob, np.asarray(self.iface.be_nodes), cols, 3 * self.nI,
                                 full_block)
            if got is not None:
                rows, Z, line, self.Zmir = got
                printf(line)
            else:
                parts.clear()
                Z = np.zeros((m.u_tmpl.getLocalSize(), 3 * self.nI))

                def take(i, z):
                    Z[:, cols[i]] = z.getArray(readonly=True)
                m.solve_columns(len(cols), by_product, take, block=block)
        unit.destroy()
        tmp.destroy()
        # (local rows, 3 n_I): H_s e_j of the interface DOFs (symmetry-zero ones: no column); None where a
        # chunk was multiplied instead (the residual check then multiplies too; the ranks agree, as on blocks)
        self.HsI = None
        if parts and all(q is not None for q in parts.values()):
            Hc = sp.hstack([parts[k] for k in sorted(parts)], format="coo")
            self.HsI = sp.csr_matrix((Hc.data, (Hc.row, cols[Hc.col])), shape=(Hc.shape[0], 3 * self.nI))
        return rows, Z

    def _zpos(self, loc):
        """Positions in Zloc's rows of the rank's local rows ``loc`` (all in Zrows: the region holds
        the interface)."""
        if self.Zrows is None:
            return loc
        pos = np.searchsorted(self.Zrows, loc)
        assert np.all(self.Zrows[np.minimum(pos, self.Zrows.size - 1)] == loc), "interface row outside Z's region"
        return pos

    def subtract_Z(self, x, d, O=None):
        """Collective: x -= Z d (this rank's rows of the soil's step solution; ``O``: Z's columns d stands for,
        all if None): on Z's rows only (``Zrows``, the region around the interface, or every row); from the
        representatives' columns where the region's columns are mirror images (``columns.MirroredZ``)."""
        if self.Zmir is not None:
            full = d if O is None else np.zeros(3 * self.nI)
            if O is not None:
                full[O] = d
            x[self.Zrows] -= self.Zmir.product(full)
            return
        Zc = self.Zloc if O is None else self.Zloc[:, O]
        if self.Zrows is None:
            x -= Zc @ d
        else:
            x[self.Zrows] -= Zc @ d

    def fem_columns(self):
        """D^{-1} T^T e_j (local rows) and C = T D^{-1} T^T (replicated) for the interface
        dofs j (3 n_I right-hand sides, solved many at a time; T^T e_j masked: a fixed dof takes
        no interface force), and a ``columns.MirroredZ`` of them or None: where the soil's columns are mirror
        images (``Zmir``) and the structure mirrors about the same planes (``columns.structure_reflections``),
        only the representatives' columns are solved and the others mirrored, D^{-1} T^T e_(g(k), c) =
        s_g(c) R_g D^{-1} T^T e_(k, c), after checking that D commutes with the reflections
        (``columns.commutation_defect``, to ``FEM_COMMUTE_TOL``), every image's right-hand side against its
        representative's mirrored and one solved image column of each reflection against its mirrored one
        (``_fem_images_hold``: the modal damping's correction too; every column solved otherwise, said in one
        line)."""
        integ = self.integ
        out = np.zeros((integ.u.getLocalSize(), 3 * self.nI))
        C = np.zeros((3 * self.nI, 3 * self.nI))
        unit = np.zeros(3 * self.nI)

        def fill(j, e):
            unit[:] = 0.0
            unit[j] = 1.0
            self.Top.spread(unit, e)
            e.pointwiseMult(e, integ.mask)

        def take(j, z):
            integ.complete_solve(z)                  # (modal damping: the solve with D, not its factors')
            out[:, j] = z.getArray(readonly=True)
            C[:, j] = self.Top.gather(z)
        R = self._fem_reflections()
        if R is not None and self._fem_rhs_hold(R, fill):
            mz = self.Zmir
            y = integ.u.duplicate()

            def take_rep(r, z):
                j = int(mz.rep_cols[r])
                take(j, z)
                for g, i, sgn in mz.images[r]:
                    R[g].mult(z, y)
                    y.scale(sgn)
                    out[:, i] = y.getArray(readonly=True)
                    C[:, i] = self.Top.gather(y)
            solve_columns(integ.ksp, integ.u, len(mz.rep_cols), lambda r, e: fill(int(mz.rep_cols[r]), e), take_rep)
            y.destroy()
            if self._fem_images_hold(R, fill, out):
                from .columns import MirroredZ
                return out, C, MirroredZ(out, mz.rep_cols, mz.images, R)
        if R is not None:
            for o in R.values():
                o.destroy()
        out[:] = 0.0
        solve_columns(integ.ksp, integ.u, 3 * self.nI, fill, take)
        return out, C, None

    def _fem_reflections(self):
        """Collective: the structure's {g: R_g} about the soil's mirror planes where the soil's interface columns
        are mirror images (``Zmir``), else None (a line says why where the soil's are but the structure's are not)."""
        if self.Zmir is None or not self.Zmir.planes:
            return None
        covered = np.zeros(3 * self.nI, bool)           # (every interface DOF a representative or an image)
        covered[self.Zmir.rep_cols] = True
        covered[[i for lst in self.Zmir.images for _, i, _ in lst]] = True
        if not covered.all():
            return None
        from .columns import structure_reflections
        got = structure_reflections(self.Zmir.planes, self.model.mesh.coords, self.model.dofmap, self.comm)
        if isinstance(got, str):
            printf(f"[ssi] interface columns: the structure's all solved ({got})")
            return None
        from .columns import commutation_defect
        defect = commutation_defect(self.integ.ksp.getOperators()[0], got)    # (D: its members, masses, supports)
        if not defect <= FEM_COMMUTE_TOL:
            return _all_solved(got, f"its matrix D commutes with the reflections only to {defect:.3g} > "
                                    f"{FEM_COMMUTE_TOL:g}")
        return got

    def _fem_rhs_hold(self, R, fill):
        """Collective: whether every image column's right-hand side T^T e_i (masked) is its representative's
        mirrored, s R_g T^T e_r, to ``columns.MIRROR_TOL`` of its largest entry; else a line, the Mats destroyed."""
        from .columns import MIRROR_TOL
        mz = self.Zmir
        b, br, y = self.integ.u.duplicate(), self.integ.u.duplicate(), self.integ.u.duplicate()
        worst = 0.0
        for r, lst in enumerate(mz.images):
            fill(int(mz.rep_cols[r]), br)
            for g, i, sgn in lst:
                fill(i, b)
                R[g].mult(br, y)
                y.scale(sgn)
                size = b.norm(self.PETSc.NormType.INFINITY)
                y.axpy(-1.0, b)
                worst = max(worst, y.norm(self.PETSc.NormType.INFINITY) / max(size, 1e-300))
        for v in (b, br, y):
            v.destroy()
        if not worst <= MIRROR_TOL:
            return _all_solved(R, f"an image's load differs from its representative's mirrored by {worst:.3g} > "
                                  f"{MIRROR_TOL:g} of its size")
        return True

    def _fem_images_hold(self, R, fill, out):
        """Collective: whether the first image column of each reflection, solved, equals its mirrored column in
        ``out`` to ``FEM_IMAGE_TOL`` of its largest entry (two solutions of the same equations: the LU's
        round-off apart); else a line (every column is then solved)."""
        from mpi4py import MPI
        mz, integ = self.Zmir, self.integ
        first = {}
        for lst in mz.images:
            for g, i, _ in lst:
                first.setdefault(g, i)
        b, z = integ.u.duplicate(), integ.u.duplicate()
        worst = 0.0
        mpi = self.comm.tompi4py()
        for g in sorted(first):
            i = first[g]
            fill(i, b)
            integ.ksp.solve(b, z)
            integ.complete_solve(z)
            a = z.getArray(readonly=True)
            diff = mpi.allreduce(float(np.abs(a - out[:, i]).max()) if a.size else 0.0, op=MPI.MAX)
            size = mpi.allreduce(float(np.abs(a).max()) if a.size else 0.0, op=MPI.MAX)
            worst = max(worst, diff / max(size, 1e-300))
        for v in (b, z):
            v.destroy()
        if not worst <= FEM_IMAGE_TOL:
            return _all_solved(R, f"a mirrored column differs from the solved one by {worst:.3g} > "
                                  f"{FEM_IMAGE_TOL:g} of its size")
        self.fem_image_check = worst
        return True

    def step(self, f_ext, uffI=None, pffI=None):
        """Collective: one coupled step; ``uffI``: the free-field displacement of the interface
        nodes at t_n (3 n_I, every rank; a seismic input in the scattered-field form: the BEM
        carries u_sc = u - u_ff, the interface and contact work with total u_b); ``pffI``: the free
        field's traction t_ff on the interface, the step's mean (3 n_I; None on a plane surface,
        where it vanishes): the structure and the contact law take p_sc + t_ff. Returns
        (u_soil scattered, p_soil scattered, info: its "p" the total traction)."""
        m, st = self.march, self.strategy
        self.uffI = np.zeros(3 * self.nI) if uffI is None else np.asarray(uffI, float)
        self.law.offset = None if pffI is None else np.asarray(pffI, float).ravel()
        with event("SSI_FEM_Step"):
            uf = st.predict(f_ext)                                 # B.1
        wI = self.Top.gather(uf)
        n = m.begin_step()                                         # history sum
        kvI0 = st.known_interface_u(wI)
        kv = m.set_known_u_owned(self.own_loc, kvI0[self.own_k])
        m.set_known_p(n)
        m.kv_u.copy(self._kv_initial)
        b = m.add_known(m.history_rhs)
        m.solve(b, m.x)                                            # B.3: y (staggered) or q (u_I = 0)
        self.sc_be.scatter(m.x, self.seq_y)
        yI = self.seq_y.getArray(readonly=True).copy()
        ev = event("SSI_Contact")
        ev.begin()
        res = st.interface(yI, wI)
        x = m.x.getArray()
        st.correct_soil(x, res, wI)
        x[self.own_loc] = np.where(np.isin(self.own_k, res["O"]), res["p"][self.own_k], x[self.own_loc])
        kv[self.own_loc] = (res["ub"] - self.uffI)[self.own_k]      # the BEM's history is scattered
        res["uff"] = self.uffI
        ev.end()
        u, p = m.store(n, m.x)
        # the BEM equations of the step with the final interface values: A x - b = 0
        res["bem_residual"] = self._bem_residual(b, (res["ub"] - self.uffI) - kvI0)
        fI = self._handover(res)
        res["force_map_error"] = self._force_map_error(p, res["p"])
        if self.law.offset is not None:         # recorded: the total traction, and the free field's share
            res["p"], res["pff"] = res["p"] + self.law.offset, self.law.offset
        with event("SSI_FEM_Step"):
            st.finish(f_ext, fI, res)
        return u, p, res

    def _handover(self, res):
        """B.5: the traction handed to the structure (interface order), the force f_I = -M p on it
        (zero on its fixed dofs: the supports take those), and the resultants of both sides."""
        tr = res["p"].copy()
        if self.c_old:                          # extrapolated, except at DOFs whose status changed
            same = np.repeat(res["closed"] == self.closed_prev, 3)
            tr = np.where(same, self.c_new * res["p"] - self.c_old * self.pI_prev, res["p"])
        self.closed_prev = res["closed"].copy()
        self.pI_prev = res["p"].copy()
        tr = self.law.total(tr)                 # + t_ff below the ground (exact step mean: not extrapolated)
        f_all = -self._m3(tr)
        fI = f_all.copy()
        fI[self.fixed_I] = 0.0                  # supports (symmetry planes) take these
        # resultants of the whole interface force (the part on fixed dofs included: it goes to the
        # supports), so that both sides balance exactly: sum_i (M p)_i = sum_j (int N_j) p_j
        f3, t3 = f_all.reshape(-1, 3), tr.reshape(-1, 3)
        res["force_fe"] = f3.sum(axis=0)
        res["force_be"] = (self.weights[:, None] * t3).sum(axis=0)
        # moments about the origin: the structure's sum (x_k + r_k) x f_k (T^T f includes r x f
        # on the rotations), the soil's int (x + r) x p dGamma by its own quadrature
        res["moment_fe"] = np.cross(self.arm, f3).sum(axis=0)
        res["moment_be"] = (np.cross(self.first_moments, t3)
                            + np.cross(self.offsets * self.weights[:, None], t3)).sum(axis=0)
        return fI

    def _m3(self, v):
        """M3 v = (M (x) I_3) v with the sparse interface mass matrix M (each component's column),
        not the dense M3: (3 n_I)^2 doubles read twice a step otherwise."""
        return np.asarray(self.Msp @ v.reshape(-1, 3)).ravel()

    def _bem_residual(self, b, dI=None):
        """Collective: ||A x - b_final|| / ||b_final||, b_final = b - H_s (kv_final - kv_initial)
        (the known interface displacements changed at open nodes); ``dI`` (3 n_I, every rank): that change
        at the interface DOFs, multiplied by H_s's interface columns kept from the set-up (``HsI``; the
        lags' products otherwise, or where it moves a symmetry-zero DOF, which has no column)."""
        m = self.march
        m.residual(m.x, b, self._r)
        if self.HsI is not None and dI is not None and not np.any(dI[self.zero]):
            self._r.getArray()[:] += self.HsI @ dI
        else:
            m.kv_u.copy(self._dkv)
            self._dkv.axpy(-1.0, self._kv_initial)
            self._r.axpy(1.0, m.mult_step_H(self._dkv, self._t))
        if m.zero_local.size:
            self._r.getArray()[m.zero_local] = 0.0
        nb = b.norm()
        return self._r.norm() / nb if nb > 0 else self._r.norm()

    def _force_map_error(self, p, pI):
        """Collective: max |F p + M p_I| over the structure's interface DOFs (the force
        matrix against the interface-order computation, node by node) [N]."""
        self.F.mult(p, self.ff)
        ref = -self._m3(pI)
        ref[self.fixed_I] = 0.0
        a = self.ff.getArray(readonly=True)[self.fown_loc]
        err = np.abs(a - ref[self.fown_k]).max() if a.size else 0.0
        mpi = self.comm.tompi4py()
        return mpi.allreduce(float(err), op=__import__("mpi4py").MPI.MAX)


def structure_mass(model):
    """Collective: the structure's total mass [kg] (the lumped masses of the x translations, point
    masses included; the modelled part with a symmetry plane), once at set-up: the nodal masses
    gathered and summed exactly rounded (math.fsum), the same number on any rank count."""
    import math
    d = model.dofmap.translation_dofs(np.arange(model.mesh.n_nodes))[:, 0]
    r0, r1 = model.m.getOwnershipRange()
    d = d[(d >= r0) & (d < r1)] - r0
    parts = model.m.getComm().tompi4py().allgather(model.m.getArray(readonly=True)[d].copy())
    return math.fsum(np.concatenate(parts))


def contact_preload(cfg, comm, model, iface):
    """Collective: the static contact pressure p_w [N/m^2] of -ssi_contact_preload (0 for none), with
    one report line: 'weight' spreads the structure's total mass x g over the interface area."""
    from .options import parse_preload, G_N
    v = parse_preload(cfg.contact_preload)
    if v is None:
        return 0.0
    if v == "weight":
        m, a = structure_mass(model), iface.area()
        p = m * G_N / a
        part = f" (the part modelled with -ssi_symmetry {cfg.symmetry})" if str(cfg.symmetry).strip() else ""
        printf(f"[ssi] contact preload: the structure's weight{part} {m:.6g} kg x {G_N:g} m/s^2 = {m * G_N:.6g} N over "
               f"the interface area {a:.6g} m^2: p_w = {p:.6g} N/m^2, uniform (a node opens when its dynamic "
               f"tension exceeds p_w + p_C = {p + cfg.contact_cohesion:.6g} N/m^2)")
        return p
    if isinstance(v, tuple):
        return earth_preload(cfg, model, iface, v[1])
    printf(f"[ssi] contact preload: p_w = {v:.6g} N/m^2, uniform (a node opens when its dynamic tension exceeds "
           f"p_w + p_C = {v + cfg.contact_cohesion:.6g} N/m^2)")
    return float(v)


def earth_preload(cfg, model, iface, k0):
    """Collective: -ssi_contact_preload earth:K0, per node p_w = n_z^2 q + (1 - n_z^2) K0 rho g |z| [N/m^2] (n_z the
    vertical component of the soil's normal n_b, rho the soil's): the lateral earth pressure at rest on walls,
    q on the bottom, chosen so that the static traction's vertical resultant sum_k a_k p_w,k n_z,k (a_k = int N_k
    dGamma, the interface mass matrix's row sums) carries the structure's weight; an edge node takes its mean
    normal's share of both. One report line."""
    from .options import G_N
    nz, z = iface.n_b[:, 2], iface.x[:, 2]
    a = np.asarray(iface.M.sum(axis=1)).ravel()
    lateral = k0 * cfg.rho * G_N * np.abs(np.minimum(z, 0.0)) * (1.0 - nz ** 2)
    w = structure_mass(model) * G_N
    q = (w - float(np.sum(a * lateral * nz))) / float(np.sum(a * nz ** 3))
    if not q > 0:
        from ..petsc import SSIError
        raise SSIError(f"-ssi_contact_preload earth:{k0:g}: the walls' lateral pressure leaves the bottom q = {q:.4g} "
                       "N/m^2 to carry the weight (<= 0): is the interface's bottom there?")
    pw = nz ** 2 * q + lateral
    printf(f"[ssi] contact preload earth: K0 {k0:g}, rho {cfg.rho:g} kg/m^3: walls up to {lateral.max():.6g} N/m^2, "
           f"bottom q = {q:.6g} N/m^2 (the weight {w:.6g} N); per node {pw.min():.6g} .. {pw.max():.6g} N/m^2")
    return pw


def _owned(dofs, vec):
    r0, r1 = vec.getOwnershipRange()
    own = (dofs >= r0) & (dofs < r1)
    return np.nonzero(own)[0], (dofs[own] - r0).astype(np.int64)


def _area_weights(mesh, iface, order=6):
    """a_k = int N_k dGamma and the first moments b_k = int x N_k dGamma over the interface
    elements (an independent quadrature of the traction resultants)."""
    from ..bem.resultants import area_moments
    return area_moments(mesh, iface.be_elems, iface.be_nodes, order)
