"""Explicit 4-wide floating-point operations for the numba kernels (njit code calls them; the word
njit here also puts this module in the compiled kernels' cache key, petsc_ssi._numba_cache_dir).

numba's LLVM pipeline does not run the SLP vectoriser, so four independent scalar updates such as
the flat traction pattern's ``P[l, c, 0:4] += (v0, v1, v2, v3) * N_c`` stay four scalar loads,
multiplies, adds and stores. ``acc4`` emits them as one vector multiply and one vector add:
IEEE operations lane by lane without fast-math flags (no contraction into fused multiply-adds,
no reassociation), so the same bits as the scalar statements (tests/bem/test_plane_kernel.py).

The block products of bem/bsr.py's template, for any block pattern (patterns.py): ``block_values``
(a block's values as a tuple), ``block_rows`` (its three row sums times a vector, scalar) and
``block_rows4``, ``block_rows4_pair`` (the same on four states at a time, for one row of blocks or two
sharing a column), each row's products summed in storage order, the same bits in every form.
"""
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
from llvmlite import ir

from .patterns import PATTERNS, rows


@intrinsic
def acc4(typingctx, arr, base, v0, v1, v2, v3, s):
    """arr[base + i] += v_i * s for i = 0..3 (arr: a contiguous float64 array, base: an index into
    its data, no bounds check), as one 4-wide multiply and add."""
    if not (isinstance(arr, types.Array) and arr.dtype == types.float64 and arr.layout == "C"
            and isinstance(base, types.Integer)
            and all(isinstance(t, types.Float) for t in (v0, v1, v2, v3, s))):
        return None
    sig = types.void(arr, base, v0, v1, v2, v3, s)

    def codegen(context, builder, signature, args):
        a, b = args[0], args[1]
        ary = context.make_array(signature.args[0])(context, builder, a)
        b = context.cast(builder, b, signature.args[1], types.intp)
        vt = ir.VectorType(ir.DoubleType(), 4)
        vptr = builder.bitcast(builder.gep(ary.data, [b]), vt.as_pointer())
        old = builder.load(vptr, align=8)
        vec = spl = ir.Constant(vt, ir.Undefined)
        sc = context.cast(builder, args[6], signature.args[6], types.float64)
        for i in range(4):
            x = context.cast(builder, args[2 + i], signature.args[2 + i], types.float64)
            idx = ir.Constant(ir.IntType(32), i)
            vec = builder.insert_element(vec, x, idx)
            spl = builder.insert_element(spl, sc, idx)
        builder.store(builder.fadd(old, builder.fmul(vec, spl)), vptr, align=8)
        return context.get_dummy_value()
    return sig, codegen



def _vec_ptr(context, builder, aty, a, idx):
    """A <4 x double>* at element ``idx`` of the contiguous float64 array ``a`` (type ``aty``)."""
    ary = context.make_array(aty)(context, builder, a)
    return builder.bitcast(builder.gep(ary.data, [idx]), ir.VectorType(ir.DoubleType(), 4).as_pointer())


def _splat(context, builder, ty, x):
    v = ir.Constant(ir.VectorType(ir.DoubleType(), 4), ir.Undefined)
    s = context.cast(builder, x, ty, types.float64)
    for i in range(4):
        v = builder.insert_element(v, s, ir.Constant(ir.IntType(32), i))
    return v


def _values(tup):
    """The pattern m of a block's values given as a tuple (UniTuple of m floats, m a pattern of
    patterns.PATTERNS), or None."""
    if isinstance(tup, types.UniTuple) and isinstance(tup.dtype, types.Float) and tup.count in PATTERNS:
        return tup.count
    return None


def _row_sums(builder, c, u, m):
    """Per block row p of pattern m, sum_j c_j u_{q_j} over the row's entries in storage order
    (patterns.rows: the first product, then one add a term, as the scalar statement ``a + b + c``
    reads), IEEE operations without fast-math flags: scalars or 4-wide vectors alike."""
    out = []
    for row in rows(m):
        s = None
        for j, q in row:
            prod = builder.fmul(c[j], u[q])
            s = prod if s is None else builder.fadd(s, prod)
        out.append(s)
    return out


def _c_float64(*arrs):
    return all(isinstance(a, types.Array) and a.dtype == types.float64 and a.layout == "C" and a.ndim == 1
               for a in arrs)


@intrinsic
def block_values(typingctx, d, k, m):
    """(d[k, 0], ..., d[k, m - 1]) in float64 (float32 values widened, exactly): the values of block k
    of a 2-D C-contiguous (blocks, m) array of pattern m (a literal int), no bounds check."""
    if not (isinstance(m, types.IntegerLiteral) and m.literal_value in PATTERNS and isinstance(d, types.Array)
            and d.ndim == 2 and d.layout == "C" and isinstance(d.dtype, types.Float)
            and isinstance(k, types.Integer)):
        return None
    n = m.literal_value
    ret = types.UniTuple(types.float64, n)
    sig = ret(d, k, m)

    def codegen(context, builder, signature, args):
        aty = signature.args[0]
        ary = context.make_array(aty)(context, builder, args[0])
        kk = context.cast(builder, args[1], signature.args[1], types.intp)
        vals = []
        for j in range(n):
            ptr = cgutils.get_item_pointer(context, builder, aty, ary, [kk, context.get_constant(types.intp, j)])
            vals.append(context.cast(builder, builder.load(ptr), aty.dtype, types.float64))
        return context.make_tuple(builder, ret, vals)
    return sig, codegen


@intrinsic
def block_rows(typingctx, c, u0, u1, u2):
    """(s0, s1, s2): the rows of a block of pattern m (its values ``c``, a tuple from ``block_values``)
    times the vector (u0, u1, u2), each row's products summed in storage order (``_row_sums``)."""
    m = _values(c)
    if m is None or not all(isinstance(u, types.Float) for u in (u0, u1, u2)):
        return None
    sig = types.UniTuple(types.float64, 3)(c, u0, u1, u2)

    def codegen(context, builder, signature, args):
        cv = [builder.extract_value(args[0], j) for j in range(m)]
        u = [context.cast(builder, args[1 + q], signature.args[1 + q], types.float64) for q in range(3)]
        return context.make_tuple(builder, signature.return_type, _row_sums(builder, cv, u, m))
    return sig, codegen


def _rows4_update(context, builder, sig, args, acc, c, u, t, m):
    """acc_p[t:t+4] += row p of the block (values: tuple argument ``c``) times the states u (three
    4-wide vectors), p = 0, 1, 2: lane by lane the scalar statements ``acc_p[t] += s_p``."""
    cv = [_splat(context, builder, sig.args[c].dtype, builder.extract_value(args[c], j)) for j in range(m)]
    for p, s in enumerate(_row_sums(builder, cv, u, m)):
        ptr = _vec_ptr(context, builder, sig.args[acc[p]], args[acc[p]], t)
        builder.store(builder.fadd(builder.load(ptr, align=8), s), ptr, align=8)


@intrinsic
def block_rows4(typingctx, acc0, acc1, acc2, t, c, x0, x1, x2):
    """States t..t+3 of one block row of a panel product (``bsr``'s template): with u_q = x_q[t:t+4],
    acc_p[t:t+4] += row p of the block (values ``c`` from ``block_values``) times u, 4-wide (1-D
    C-contiguous float64 arrays, no bounds check); lane by lane the scalar ``block_rows``."""
    m = _values(c)
    if m is None or not (_c_float64(acc0, acc1, acc2, x0, x1, x2) and isinstance(t, types.Integer)):
        return None
    sig = types.void(acc0, acc1, acc2, t, c, x0, x1, x2)

    def codegen(context, builder, signature, args):
        tt = context.cast(builder, args[3], signature.args[3], types.intp)
        u = [builder.load(_vec_ptr(context, builder, signature.args[k], args[k], tt), align=8) for k in (5, 6, 7)]
        _rows4_update(context, builder, signature, args, (0, 1, 2), 4, u, tt, m)
        return context.get_dummy_value()
    return sig, codegen


@intrinsic
def block_rows4_pair(typingctx, a0, a1, a2, e0, e1, e2, t, cp, cq, x0, x1, x2):
    """``block_rows4`` for two rows of blocks holding the same column (``bsr``'s two-row panel): the
    states x_q[t:t+4] loaded once, row one's block ``cp`` into a0..a2, row two's ``cq`` into e0..e2."""
    m = _values(cp)
    if m is None or _values(cq) != m or not (_c_float64(a0, a1, a2, e0, e1, e2, x0, x1, x2)
                                             and isinstance(t, types.Integer)):
        return None
    sig = types.void(a0, a1, a2, e0, e1, e2, t, cp, cq, x0, x1, x2)

    def codegen(context, builder, signature, args):
        tt = context.cast(builder, args[6], signature.args[6], types.intp)
        u = [builder.load(_vec_ptr(context, builder, signature.args[k], args[k], tt), align=8) for k in (9, 10, 11)]
        _rows4_update(context, builder, signature, args, (0, 1, 2), 7, u, tt, m)
        _rows4_update(context, builder, signature, args, (3, 4, 5), 8, u, tt, m)
        return context.get_dummy_value()
    return sig, codegen


def _lit(x, lo, hi):
    return isinstance(x, types.IntegerLiteral) and lo <= x.literal_value <= hi


@intrinsic
def cmac_tile(typingctx, K, kb, KJ, X, xb, XS, out, ob, OS, n, T, ms, mo, vl, kp):
    """A register tile of complex multiply-adds in frequency lanes (``lanes.lane_products``' micro-kernel):
    for the ms x mo outputs (s, o) and the vl lanes q0..q0+vl-1,
        out[ob + s OS + o 2T + t T + q] += sum_{i < n} X[xb + s XS + i 2T + .] K[kb + i KJ + o kp T + .]
    complex (t = 0 the real part, t = 1 the imaginary part, T elements apart), the ms mo complex sums kept
    in vector registers over the n terms (4 fused multiply-adds a term and output, in the order i, as the
    scalar loop with contraction sums them). kp = 2: K complex (its parts T apart); kp = 1: K real (one part a
    column: 2 fused multiply-adds a term, the real and the imaginary part of X times it). K and out are
    C-contiguous float64 arrays, X float64 or float32 (widened exactly); offsets are flat element indices,
    not checked. ms, mo, vl, kp literal ints."""
    if not (_lit(ms, 1, 8) and _lit(mo, 1, 8) and vl in (types.IntegerLiteral(4), types.IntegerLiteral(8))
            and _lit(kp, 1, 2)
            and all(isinstance(a, types.Array) and a.layout == "C" for a in (K, X, out))
            and K.dtype == types.float64 and out.dtype == types.float64 and X.dtype in (types.float64, types.float32)
            and all(isinstance(a, types.Integer) for a in (kb, KJ, xb, XS, ob, OS, n, T))):
        return None
    MS, MO, VL, KP = ms.literal_value, mo.literal_value, vl.literal_value, kp.literal_value
    sig = types.void(K, kb, KJ, X, xb, XS, out, ob, OS, n, T, ms, mo, vl, kp)

    def codegen(context, builder, signature, args):
        st = signature.args
        i64 = ir.IntType(64)
        vd = ir.VectorType(ir.DoubleType(), VL)
        single = st[3].dtype == types.float32
        vx = ir.VectorType(ir.FloatType() if single else ir.DoubleType(), VL)
        fma = cgutils.get_or_insert_function(builder.module, ir.FunctionType(vd, [vd, vd, vd]), f"llvm.fma.v{VL}f64")

        def idx(k):
            return context.cast(builder, args[k], st[k], types.intp)
        Kd = context.make_array(st[0])(context, builder, args[0]).data
        Xd = context.make_array(st[3])(context, builder, args[3]).data
        Od = context.make_array(st[6])(context, builder, args[6]).data
        kb_, KJ_, xb_, XS_, ob_, OS_, n_, T_ = (idx(k) for k in (1, 2, 4, 5, 7, 8, 9, 10))
        T2 = builder.mul(T_, ir.Constant(i64, 2))

        def vload(data, off, vt):
            return builder.load(builder.bitcast(builder.gep(data, [off]), vt.as_pointer()), align=8)
        zero = ir.Constant(vd, [0.0] * VL)
        accs = [[[cgutils.alloca_once_value(builder, zero) for _ in range(2)] for _ in range(MO)] for _ in range(MS)]
        with cgutils.for_range(builder, n_) as loop:
            i = loop.index
            ko = builder.add(kb_, builder.mul(i, KJ_))
            xo = builder.add(xb_, builder.mul(i, T2))
            kv = []
            for o in range(MO):
                base = builder.add(ko, builder.mul(ir.Constant(i64, o), T2 if KP == 2 else T_))
                kv.append((vload(Kd, base, vd), vload(Kd, builder.add(base, T_), vd) if KP == 2 else None))
            for s in range(MS):
                base = builder.add(xo, builder.mul(ir.Constant(i64, s), XS_))
                xr, xi = vload(Xd, base, vx), vload(Xd, builder.add(base, T_), vx)
                if single:
                    xr, xi = builder.fpext(xr, vd), builder.fpext(xi, vd)
                nxi = builder.fneg(xi)
                for o in range(MO):
                    kr, ki = kv[o]
                    pr, pi = accs[s][o]
                    if KP == 1:             # (a real kernel: its product with X's two parts)
                        ar = builder.call(fma, [xr, kr, builder.load(pr)])
                        ai = builder.call(fma, [xi, kr, builder.load(pi)])
                    else:
                        ar = builder.call(fma, [nxi, ki, builder.call(fma, [xr, kr, builder.load(pr)])])
                        ai = builder.call(fma, [xi, kr, builder.call(fma, [xr, ki, builder.load(pi)])])
                    builder.store(ar, pr)
                    builder.store(ai, pi)
        for s in range(MS):
            for o in range(MO):
                base = builder.add(builder.add(ob_, builder.mul(ir.Constant(i64, s), OS_)),
                                   builder.mul(ir.Constant(i64, o), T2))
                for t, off in enumerate((base, builder.add(base, T_))):
                    ptr = builder.bitcast(builder.gep(Od, [off]), vd.as_pointer())
                    builder.store(builder.fadd(builder.load(ptr, align=8), builder.load(accs[s][o][t])), ptr, align=8)
        return context.get_dummy_value()
    return sig, codegen
