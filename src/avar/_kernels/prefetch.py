"""A software prefetch for compiled loops that read memory the hardware prefetcher cannot foresee.

The CPU's stream prefetchers follow sequential reads within a 4 KiB page. A loop that reads
pieces of a series far apart (every ``P``-th piece of :mod:`avar._kernels.allan.far`) starts
every piece with misses to main memory: on float32 pieces of 1024 samples read 8 pieces apart,
1.04 ns a sample against 0.63 ns contiguous (one core). Announcing the next piece while the
current one is read (one :func:`prefetch` per cache line) brings it back to 0.64 ns.

:func:`prefetch` emits LLVM's ``llvm.prefetch`` (read, high locality): a hint only, it never
faults and changes no value; on a CPU without a prefetch instruction LLVM drops it.
"""

from __future__ import annotations

import llvmlite.binding as llvm
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

#: The intrinsic's name carries its pointer type: ``p0`` for LLVM's opaque pointers (15 and
#: later), ``p0i8`` before. (A name of the other kind is renamed by LLVM's auto-upgrade of
#: ``llvm.prefetch`` declarations when the module is parsed.)
_NAME = "llvm.prefetch.p0" if llvm.llvm_version_info[0] >= 15 else "llvm.prefetch.p0i8"


@intrinsic
def prefetch(typingctx, values, index):
    """Ask for the cache line holding ``values[index]`` (a 1-d array, ``index`` in range)."""
    if not (isinstance(values, types.Array) and values.ndim == 1 and isinstance(index, types.Integer)):
        return None
    sig = types.void(values, index)

    def codegen(context, builder, signature, args):
        array_type = signature.args[0]
        array = context.make_array(array_type)(context, builder, args[0])
        pointer = cgutils.get_item_pointer(context, builder, array_type, array, [args[1]], wraparound=False)
        byte_pointer = ir.IntType(8).as_pointer()
        i32 = ir.IntType(32)
        function = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [byte_pointer, i32, i32, i32]), _NAME)
        # (address, read = 0, locality = 3: keep in every cache level, data cache = 1)
        builder.call(function, [builder.bitcast(pointer, byte_pointer), i32(0), i32(3), i32(1)])
        return context.get_dummy_value()

    return sig, codegen
