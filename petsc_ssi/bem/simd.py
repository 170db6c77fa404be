"""Explicit 4-wide floating-point operations for the numba kernels (njit code calls them; the word
njit here also puts this module in the compiled kernels' cache key, petsc_ssi._numba_cache_dir).

numba's LLVM pipeline does not run the SLP vectoriser, so four independent scalar updates such as
the flat traction pattern's ``P[l, c, 0:4] += (v0, v1, v2, v3) * N_c`` stay four scalar loads,
multiplies, adds and stores. ``acc4`` emits them as one vector multiply and one vector add:
IEEE operations lane by lane without fast-math flags (no contraction into fused multiply-adds,
no reassociation), so the same bits as the scalar statements (tests/bem/test_plane_kernel.py).
"""
from numba import types
from numba.extending import intrinsic
from llvmlite import ir


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


def _h4_update(context, builder, sig, args, acc, coef, u, t):
    """acc0 += c02 u2; acc1 += c12 u2; acc2 += c20 u0 + c21 u1 on four states (the flat H pattern's
    row update of ``bsr._panel_h4``, lane by lane as its scalar statements)."""
    ps = [_vec_ptr(context, builder, sig.args[k], args[k], t) for k in acc]
    c = [_splat(context, builder, sig.args[k], args[k]) for k in coef]
    u0, u1, u2 = u
    builder.store(builder.fadd(builder.load(ps[0], align=8), builder.fmul(c[0], u2)), ps[0], align=8)
    builder.store(builder.fadd(builder.load(ps[1], align=8), builder.fmul(c[1], u2)), ps[1], align=8)
    s = builder.fadd(builder.fmul(c[2], u0), builder.fmul(c[3], u1))
    builder.store(builder.fadd(builder.load(ps[2], align=8), s), ps[2], align=8)


def _c_float64(*arrs):
    return all(isinstance(a, types.Array) and a.dtype == types.float64 and a.layout == "C" and a.ndim == 1
               for a in arrs)


@intrinsic
def h4_4(typingctx, acc0, acc1, acc2, t, c02, c12, c20, c21, x0, x1, x2):
    """States t..t+3 of one row of a flat-H panel product (``bsr._panel_h4``): with u_j = x_j[t:t+4],
    acc0 += c02 u2, acc1 += c12 u2, acc2 += (c20 u0 + c21 u1), 4-wide (1-D C-contiguous float64
    arrays, no bounds check)."""
    if not (_c_float64(acc0, acc1, acc2, x0, x1, x2) and isinstance(t, types.Integer)):
        return None
    sig = types.void(acc0, acc1, acc2, t, c02, c12, c20, c21, x0, x1, x2)

    def codegen(context, builder, signature, args):
        tt = context.cast(builder, args[3], signature.args[3], types.intp)
        u = [builder.load(_vec_ptr(context, builder, signature.args[k], args[k], tt), align=8) for k in (8, 9, 10)]
        _h4_update(context, builder, signature, args, (0, 1, 2), (4, 5, 6, 7), u, tt)
        return context.get_dummy_value()
    return sig, codegen


@intrinsic
def h4pair_4(typingctx, a0, a1, a2, e0, e1, e2, t, p02, p12, p20, p21, q02, q12, q20, q21, x0, x1, x2):
    """``h4_4`` for two rows holding the same column (``bsr._panel_h4_pair``): the states x_j[t:t+4]
    loaded once, row one's coefficients p into a0..a2, row two's q into e0..e2."""
    if not (_c_float64(a0, a1, a2, e0, e1, e2, x0, x1, x2) and isinstance(t, types.Integer)):
        return None
    sig = types.void(a0, a1, a2, e0, e1, e2, t, p02, p12, p20, p21, q02, q12, q20, q21, x0, x1, x2)

    def codegen(context, builder, signature, args):
        tt = context.cast(builder, args[6], signature.args[6], types.intp)
        u = [builder.load(_vec_ptr(context, builder, signature.args[k], args[k], tt), align=8) for k in (15, 16, 17)]
        _h4_update(context, builder, signature, args, (0, 1, 2), (7, 8, 9, 10), u, tt)
        _h4_update(context, builder, signature, args, (3, 4, 5), (11, 12, 13, 14), u, tt)
        return context.get_dummy_value()
    return sig, codegen
