"""liblzf decompression (the body of a PCD ``binary_compressed`` file), compiled with numba."""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["lzf_decompress"]


@numba.njit(cache=True)
def lzf_decompress(src: NDArray[np.uint8],  # pragma: no cover - compiled
                   size: int) -> NDArray[np.uint8]:
    """liblzf decompression (PCD binary_compressed); empty result on corrupt input."""
    out = np.empty(size, np.uint8)
    ip, op = 0, 0
    while ip < src.size:
        ctrl = int(src[ip])
        ip += 1
        if ctrl < 32:  # literal run of ctrl + 1 bytes
            n = ctrl + 1
            if ip + n > src.size or op + n > size:
                return out[:0]
            for k in range(n):  # element by element: no shape check to compile
                out[op + k] = src[ip + k]
            ip += n
            op += n
            continue
        n = ctrl >> 5  # back reference
        if n == 7:
            if ip >= src.size:
                return out[:0]
            n += int(src[ip])
            ip += 1
        if ip >= src.size:
            return out[:0]
        ref = op - ((ctrl & 0x1F) << 8) - 1 - int(src[ip])
        ip += 1
        n += 2
        if ref < 0 or op + n > size:
            return out[:0]
        for k in range(n):  # byte by byte: the source may overlap the output
            out[op + k] = out[ref + k]
        op += n
    return out[:op]
