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

