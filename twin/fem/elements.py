"""The Lagrange triangles the thermal and structural problems are built on."""

from __future__ import annotations

from skfem import Element, ElementTriP1, ElementTriP2

ELEMENTS = {1: ElementTriP1, 2: ElementTriP2}


def element_for(order: int) -> Element:
    """P1 (order 1) or P2 (order 2) scalar triangle element."""
    try:
        return ELEMENTS[order]()
    except KeyError:
        raise ValueError(f"element order must be 1 (P1) or 2 (P2), got {order!r}") from None
