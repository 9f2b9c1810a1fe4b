"""Rays walked in lock-step, four at a time, by one LLVM vector loop (the native Octomap's
hot loop), and a prefetch hint.

A ray's walk (:func:`alte.mappers.octree.raycast.flat_starts` gives its start) is OctoMap's
``computeRayKeys``: pick the axis with the smallest tMax (ties go to z, then y), add
its tDelta, move one voxel, stop at the end voxel or when min(tMax) passes the ray's
length, or after the step limit. Its branches are as good as random (the axis changes
at most steps of a LiDAR ray), so a scalar walk stalls on mispredictions. Here
:data:`LANES` rays take each step together as vector compares, selects and adds on the
same float64 values in the same order (so bit for bit OctoMap's keys), and set their
voxel bits in a flat grid (x rows, one bit per voxel). The loop is LLVM IR built with
llvmlite (:func:`_advance`) because numba does not vectorise across independent walks;
it returns to numba only when a lane finishes, to load the next ray.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numba
import numpy as np
from llvmlite import ir  # type: ignore[import-untyped]  # numba's IR builder, untyped
from numba import types
from numba.core.typing.context import BaseContext
from numba.core.typing.templates import Signature
from numba.extending import intrinsic
from numpy.typing import NDArray

__all__ = ["FLOATS", "INTS", "LANES", "prefetch", "walk_lanes"]

#: Rays per vector step.
LANES = 4
#: Float start data of a ray: tMax x, y, z; tDelta x, y, z; its length.
FLOATS = 7
#: Integer start data: bit index of its voxel, bit steps along x, y, z, bit index of the
#: end voxel, steps allowed.
INTS = 6

_F64, _I64, _I32 = ir.DoubleType(), ir.IntType(64), ir.IntType(32)
_VF, _VI = ir.VectorType(_F64, LANES), ir.VectorType(_I64, LANES)
_VB = ir.VectorType(ir.IntType(1), LANES)


class _ArrayStruct(Protocol):
    """numba's struct of an array argument, as the code generators read it."""

    data: ir.Value


class _Target(Protocol):
    """What the code generators ask of numba's target context (``numba.core.base``, whose
    methods carry no annotations)."""

    def make_array(self, typ: types.Type
                   ) -> Callable[[_Target, ir.IRBuilder, ir.Value], _ArrayStruct]: ...
    def get_dummy_value(self) -> ir.Value: ...


#: An intrinsic's code generator: (target context, IR builder, signature, argument values).
Codegen = Callable[[_Target, ir.IRBuilder, Signature, list[ir.Value]], ir.Value]


def _vectors(builder: ir.IRBuilder, base: ir.Value, kind: ir.VectorType,
             count: int) -> list[ir.Value]:
    """Pointers to ``count`` consecutive vectors of ``kind`` from ``base``."""
    return [builder.bitcast(builder.gep(base, [ir.Constant(_I64, k * LANES)]),
                            kind.as_pointer()) for k in range(count)]


def _step(b: ir.IRBuilder, t: list[ir.Value], fixed: list[ir.Value],
          ivec: list[ir.Value]) -> tuple[list[ir.Value], ir.Value, ir.Value, ir.Value, ir.Value]:
    """One voxel step of every lane: new (tx, ty, tz), bit index, steps left, and the
    lanes that stopped before (end voxel, past the length) or after this voxel."""
    (tx, ty, tz), (dx, dy, dz, length), (idx, jx, jy, jz, end, left) = t, fixed, ivec
    ones, zf, zi = (ir.Constant(_VB, [1] * LANES), ir.Constant(_VF, [0.0] * LANES),
                    ir.Constant(_VI, [0] * LANES))
    xy = b.fcmp_ordered("<", tx, ty)
    ax = b.and_(xy, b.fcmp_ordered("<", tx, tz))
    ay = b.and_(b.xor(xy, ones), b.fcmp_ordered("<", ty, tz))
    az = b.xor(b.or_(ax, ay), ones)
    new = [b.fadd(tx, b.select(ax, dx, zf)), b.fadd(ty, b.select(ay, dy, zf)),
           b.fadd(tz, b.select(az, dz, zf))]
    idx = b.add(b.add(idx, b.select(ax, jx, zi)),
                b.add(b.select(ay, jy, zi), b.select(az, jz, zi)))
    left = b.sub(left, ir.Constant(_VI, [1] * LANES))
    low = b.select(b.fcmp_ordered("<", new[0], new[1]), new[0], new[1])
    low = b.select(b.fcmp_ordered("<", low, new[2]), low, new[2])
    before = b.or_(b.icmp_signed("==", idx, end), b.fcmp_ordered(">", low, length))
    return new, idx, left, b.or_(before, b.icmp_signed("==", left, zi)), before


def _set_bits(b: ir.IRBuilder, grid: ir.Value, where: ir.Value) -> None:
    """OR bit ``where[l] & 63`` into word ``where[l] >> 6`` of ``grid`` for every lane."""
    for lane in range(LANES):
        w = b.extract_element(where, ir.Constant(_I32, lane))
        word = b.gep(grid, [b.ashr(w, ir.Constant(_I64, 6))])
        bit = b.shl(ir.Constant(_I64, 1), b.and_(w, ir.Constant(_I64, 63)))
        b.store(b.or_(b.load(word), bit), word)


def _advance_codegen(context: _Target, b: ir.IRBuilder, sig: Signature,
                     args: list[ir.Value]) -> ir.Value:
    fptr = _vectors(b, context.make_array(sig.args[0])(context, b, args[0]).data, _VF, FLOATS)
    iptr = _vectors(b, context.make_array(sig.args[1])(context, b, args[1]).data, _VI, INTS)
    grid = b.bitcast(context.make_array(sig.args[2])(context, b, args[2]).data,
                     _I64.as_pointer())
    start = [b.load(p, align=8) for p in fptr]
    ivec = [b.load(p, align=8) for p in iptr]
    dummy = b.shuffle_vector(b.insert_element(ir.Constant(_VI, ir.Undefined), args[3],
                                              ir.Constant(_I32, 0)),
                             ir.Constant(_VI, ir.Undefined), ir.Constant(
                                 ir.VectorType(_I32, LANES), [0] * LANES))
    entry, loop, done = b.block, b.append_basic_block("lanes"), b.append_basic_block("out")
    b.branch(loop)
    b.position_at_end(loop)
    state = [b.phi(_VF) for _ in range(3)] + [b.phi(_VI), b.phi(_VI)]
    for phi, value in zip(state, [*start[:3], ivec[0], ivec[5]], strict=True):
        phi.add_incoming(value, entry)
    t, idx, left, stop, before = _step(b, state[:3], start[3:], [state[3], *ivec[1:5], state[4]])
    _set_bits(b, grid, b.select(before, dummy, idx))
    for phi, value in zip(state, [*t, idx, left], strict=True):
        phi.add_incoming(value, loop)
    mask = b.bitcast(stop, ir.IntType(LANES))
    b.cbranch(b.icmp_unsigned("!=", mask, ir.Constant(ir.IntType(LANES), 0)), done, loop)
    b.position_at_end(done)
    for ptr, value in zip([*fptr[:3], iptr[0], iptr[5]], [*t, idx, left], strict=True):
        b.store(value, ptr, align=8)
    return b.zext(mask, _I64)


@intrinsic
def _advance(typingctx: BaseContext, floats: types.Type, ints: types.Type, grid: types.Type,
             dummy: types.Type) -> tuple[Signature, Codegen]:
    """Step every lane until one stops; lane state lives in ``floats`` (FLOATS x LANES)
    and ``ints`` (INTS x LANES), stored back on return; returns the stopped lanes' mask.
    A lane's bit goes to ``dummy`` (a spare bit past the grid) when it stops before
    its voxel."""
    return types.int64(floats, ints, grid, dummy), _advance_codegen


def _prefetch_codegen(context: _Target, b: ir.IRBuilder, sig: Signature,
                      args: list[ir.Value]) -> ir.Value:
    ptr = b.gep(context.make_array(sig.args[0])(context, b, args[0]).data, [args[1]])
    i8p = ir.IntType(8).as_pointer()
    fn = b.module.declare_intrinsic("llvm.prefetch", fnty=ir.FunctionType(
        ir.VoidType(), [i8p, _I32, _I32, _I32]))
    b.call(fn, [b.bitcast(ptr, i8p), ir.Constant(_I32, 1), ir.Constant(_I32, 3),
                ir.Constant(_I32, 1)])
    return context.get_dummy_value()


@intrinsic
def prefetch(typingctx: BaseContext, array: types.Type, index: types.Type,
             ) -> tuple[Signature, Codegen]:
    """Hint that element ``index`` of a C-contiguous ``array`` (flat) is written soon."""
    return types.void(array, index), _prefetch_codegen


@numba.njit(cache=True, inline="always")
def _load(lane: int, ray: int, state: tuple[NDArray[np.float64], NDArray[np.int64]],
          starts: tuple[NDArray[np.float64], NDArray[np.int64]], dummy: int) -> int:
    """Start ``ray`` in ``lane`` (1), or park the lane (0) when no ray is left: a parked
    lane steps in place on the spare bit and never stops."""
    floats, ints = state
    if ray < starts[0].shape[0]:
        for f in range(FLOATS):
            floats[f * LANES + lane] = starts[0][ray, f]
        for f in range(INTS):
            ints[f * LANES + lane] = starts[1][ray, f]
        return 1
    for f in range(FLOATS):
        floats[f * LANES + lane] = 0.0
    floats[(FLOATS - 1) * LANES + lane] = 1.0
    for f in range(INTS):
        ints[f * LANES + lane] = 0
    ints[lane], ints[4 * LANES + lane], ints[5 * LANES + lane] = dummy, -1, 1 << 62
    return 0


@numba.njit(cache=True)
def walk_lanes(floats: NDArray[np.float64], ints: NDArray[np.int64], grid: NDArray[np.uint64],
               dummy: int) -> None:
    """Set the bits of every ray's free voxels (start data: ``floats`` (R, FLOATS) and
    ``ints`` (R, INTS)) in ``grid``; ``dummy`` is a spare bit index past the grid's."""
    if floats.shape[0] == 0:
        return
    first = ints[0, 0]  # every ray starts in the origin's voxel
    grid[first >> 6] |= np.uint64(1) << np.uint64(first & 63)
    state = (np.empty(FLOATS * LANES), np.empty(INTS * LANES, dtype=np.int64))
    ray, live = 0, 0
    for lane in range(LANES):
        live += _load(lane, ray, state, (floats, ints), dummy)
        ray += 1
    while live:
        mask: int = _advance(state[0], state[1], grid, dummy)  # type: ignore[call-arg, arg-type]  # numba intrinsic
        for lane in range(LANES):
            if (mask >> lane) & 1:
                live -= 1 - _load(lane, ray, state, (floats, ints), dummy)
                ray += 1
