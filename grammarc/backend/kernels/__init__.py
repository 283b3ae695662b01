"""The derivation's numba kernels on shape columns: split and repeat fan-out (``split``), scope arithmetic
fused into single passes (``scope``), stable orderings by a small key (``order``)."""
