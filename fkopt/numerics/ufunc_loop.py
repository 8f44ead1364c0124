"""numpy's own inner loop of a one-argument float64 ufunc (``np.tan``), callable from compiled code.

Why. The compiled swarm iterations must use numpy's tangents, not the C library's (an ulp apart on
~0.7 % of inputs with numpy's SIMD loops, and a swarm turns an ulp into another run:
:mod:`fkopt.mechanisms.rps3_kernels`). Calling ``np.tan`` from Python between compiled kernels
costs the kernels' dispatch and the Python around them on every iteration. numpy itself computes
``np.tan(a, out=b)`` on contiguous float64 arrays by one call of the ufunc's inner loop
``loop(args, dimensions, steps, data)`` (the legacy ``PyUFuncGenericFunction`` that numpy's
default loop selector takes: the first ``d->d`` entry of the ufunc's type table). Called from
compiled code with the same pointers, length and strides, that loop gives ``np.tan``'s values
because it *is* ``np.tan``'s code -- whichever SIMD variant numpy chose for this CPU at import.

:func:`unary_loop` reads the loop's address from the ufunc object (``PyUFuncObject``'s public
layout in numpy's ``ufuncobject.h``: functions, data, ntypes, name, types), checks that layout
against what Python sees of the same ufunc (name, nin, nout, the type table), and then checks
the loop against the ufunc itself, bit for bit, on a probe of lengths 0..67 (SIMD bodies and
tails) and values from tiny to huge, zeros, infinities and NaN. Anything unexpected (another
Python implementation, another layout, a probe that differs) gives None, and callers keep
calling the ufunc from Python. :func:`call_unary_loop` is the compiled call.

Importing this module imports numba; :mod:`fkopt.mechanisms.rps3_kernels` imports it on the
compiled path only.
"""
from __future__ import annotations

import ctypes
import sys
from functools import lru_cache

import numpy as np
from numba import types
from numba.core import cgutils
from numba.core.extending import intrinsic
from llvmlite import ir

from fkopt.numerics.jit import njit


class _UFuncHead(ctypes.Structure):
    """The start of numpy's ``PyUFuncObject`` (numpy/_core/include/numpy/ufuncobject.h)."""

    _fields_ = [("ob_refcnt", ctypes.c_ssize_t), ("ob_type", ctypes.c_void_p),
                ("nin", ctypes.c_int), ("nout", ctypes.c_int), ("nargs", ctypes.c_int), ("identity", ctypes.c_int),
                ("functions", ctypes.c_void_p), ("data", ctypes.c_void_p), ("ntypes", ctypes.c_int),
                ("reserved1", ctypes.c_int), ("name", ctypes.c_char_p), ("types", ctypes.c_void_p)]


def _probe_values() -> list[np.ndarray]:
    """Arrays of lengths 0..67 and 1000 (every SIMD body and tail length of 2..16 lanes) of
    values across scales, signed zeros, infinities and NaN, from a fixed seed."""
    rng = np.random.default_rng(20261206)
    special = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1e-310, -1e-300, 1e300, np.pi / 2, -np.pi / 4])
    out = []
    for n in list(range(68)) + [1000]:
        scale = 10.0 ** rng.uniform(-8, 8, n)
        out.append(rng.uniform(-1.0, 1.0, n) * scale)
    out.append(special)
    return out


def _read_loop(ufunc) -> tuple[int, int] | None:
    """(address of the inner loop, its data pointer) of ``ufunc``'s first d->d entry, if the
    object's layout reads as the ufunc Python sees; else None."""
    if sys.implementation.name != "cpython" or not isinstance(ufunc, np.ufunc):
        return None
    head = _UFuncHead.from_address(id(ufunc))
    if (head.nin, head.nout, head.nargs, head.ntypes) != (ufunc.nin, ufunc.nout, ufunc.nargs, ufunc.ntypes):
        return None
    if head.name is None or head.name.decode("ascii", "replace") != ufunc.__name__ or not head.types:
        return None
    if (ufunc.nin, ufunc.nout) != (1, 1):
        return None
    table = ctypes.string_at(head.types, head.ntypes * head.nargs)
    want = [(np.dtype(s[0]).num, np.dtype(s[-1]).num) for s in ufunc.types]      # e.g. "d->d"
    if [tuple(table[2 * i:2 * i + 2]) for i in range(head.ntypes)] != want:
        return None
    double = np.dtype(np.float64).num
    index = next((i for i in range(head.ntypes) if table[2 * i] == double and table[2 * i + 1] == double), None)
    if index is None or not head.functions:
        return None
    fn = ctypes.c_void_p.from_address(head.functions + index * ctypes.sizeof(ctypes.c_void_p)).value
    data = ctypes.c_void_p.from_address(head.data + index * ctypes.sizeof(ctypes.c_void_p)).value if head.data else None
    return (fn, data or 0) if fn else None


@lru_cache(maxsize=8)
def unary_loop(ufunc) -> tuple[int, int] | None:
    """(loop, data) of ``ufunc``'s float64 inner loop for :func:`call_unary_loop`, or None when it
    cannot be read or does not reproduce ``ufunc`` bit for bit on the probe (module docstring)."""
    try:
        loop = _read_loop(ufunc)
    except (ValueError, OSError, TypeError):
        return None
    if loop is None:
        return None
    for a in _probe_values():
        want = np.full(a.size + 2, -7.0)
        got = np.full(a.size + 2, -7.0)
        with np.errstate(all="ignore"):
            ufunc(a, out=want[1:-1])
        _apply(loop[0], loop[1], np.concatenate(([0.0], a, [0.0])), got, 1, a.size)
        if not np.array_equal(want.view(np.int64), got.view(np.int64)):   # bits, NaN payloads included
            return None
    return loop


@intrinsic
def _call(typingctx, fn, data, src, dst, start, count):
    """``loop(args, dimensions, steps, data)`` at address ``fn`` on src[start:start + count] into
    dst[start:start + count] (1-D C-contiguous float64): args, dimensions and steps on the stack."""
    ok = all(isinstance(a, types.Array) and a.ndim == 1 and a.layout == "C" and a.dtype == types.float64
             for a in (src, dst))
    if not ok or not all(isinstance(t, types.Integer) for t in (fn, data, start, count)):
        return None
    sig = types.void(fn, data, src, dst, start, count)

    def codegen(context, builder, signature, args):
        fn_, data_, src_, dst_, start_, count_ = args
        intp = context.get_value_type(types.intp)
        i8p = ir.IntType(8).as_pointer()
        a = context.make_array(signature.args[2])(context, builder, src_)
        b = context.make_array(signature.args[3])(context, builder, dst_)
        first = context.cast(builder, start_, signature.args[4], types.intp)
        ptrs = cgutils.alloca_once(builder, i8p, size=2)
        dims = cgutils.alloca_once(builder, intp, size=1)
        steps = cgutils.alloca_once(builder, intp, size=2)
        one = ir.Constant(intp, 1)
        builder.store(builder.bitcast(builder.gep(a.data, [first]), i8p), ptrs)
        builder.store(builder.bitcast(builder.gep(b.data, [first]), i8p), builder.gep(ptrs, [one]))
        builder.store(context.cast(builder, count_, signature.args[5], types.intp), dims)
        eight = ir.Constant(intp, 8)
        builder.store(eight, steps)
        builder.store(eight, builder.gep(steps, [one]))
        fnty = ir.FunctionType(ir.VoidType(), [i8p.as_pointer(), intp.as_pointer(), intp.as_pointer(), i8p])
        target = builder.inttoptr(fn_, fnty.as_pointer())
        builder.call(target, [ptrs, dims, steps, builder.inttoptr(data_, i8p)])
        return context.get_dummy_value()
    return sig, codegen


@njit(cache=True)
def call_unary_loop(fn, data, src, dst, start, count):
    """numpy's ufunc loop (fn, data) of :func:`unary_loop` on src[start:start + count] into
    dst[start:start + count], as ``ufunc(src[start:stop], out=dst[start:stop])`` computes it
    (nothing for count 0; the range must lie inside both arrays)."""
    if count <= 0:
        return
    if start < 0 or start + count > src.shape[0] or start + count > dst.shape[0]:
        raise IndexError("call_unary_loop: range outside the arrays")
    _call(fn, data, src, dst, start, count)


def _apply(fn, data, src, dst, start, count):
    call_unary_loop(int(fn), int(data), src, dst, int(start), int(count))
