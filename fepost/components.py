"""Connected parts of a mesh: elements (or faces) joined through the nodes they share.

Why not always ``scipy.sparse.csgraph.connected_components``: importing it takes
0.4–0.6 s (``scipy.sparse`` with its array-API layer, then ``scipy.sparse.linalg``
and ``scipy.linalg`` through the package's ``__init__``), about what reading a
million-node Exodus file takes otherwise, and the reader needs it for every volume
mesh, usually on a small graph (the elements that touch the loaded nodes). Up to
`SCIPY_FROM` pairs the parts are found here; on larger graphs scipy's labelling is
faster than its import costs.

The graph is bipartite (items and the nodes they list), which whole-array
union–find handles in a few passes: every pair (item, node) that joins two roots
hooks the larger onto the smaller (a root only ever points to a smaller index, so no
cycle forms), then pointers jump to their roots, until no pair joins two roots. A
root is therefore the smallest index of its part, and the parts are numbered in the
order of their smallest index — the numbering of scipy's breadth-first labelling,
which `tests/test_components.py` checks on random graphs.
"""

from __future__ import annotations

import numpy as np

from .errors import ArgumentError

#: From this many (item, node) pairs on, scipy's connected_components (its import then
#: costs less than the passes here: 4 M pairs take 1.6 s here, 0.5 s with scipy).
SCIPY_FROM = 1 << 21


def item_parts(items: np.ndarray, nodes: np.ndarray, n_items: int) -> tuple[int, np.ndarray]:
    """(count, labels) of the parts of ``n_items`` items joined through shared nodes.

    ``items`` and ``nodes`` (equal length): item ``items[k]`` lists node ``nodes[k]``
    (any non-negative node numbers). ``labels`` (n_items,) numbers the parts 0, 1, …
    in the order of their first item; an item that lists no node is a part of its own.
    """
    items = np.asarray(items, np.int64).ravel()
    nodes = np.asarray(nodes, np.int64).ravel()
    if items.shape != nodes.shape:
        raise ArgumentError(f"items and nodes must have one length, got {items.size} and {nodes.size}")
    if items.size and (items.min() < 0 or items.max() >= n_items or nodes.min() < 0):
        raise ArgumentError("items must lie in [0, n_items) and nodes must be non-negative")
    if items.size > SCIPY_FROM:
        return _scipy_parts(items, nodes, n_items)
    top = int(nodes.max()) + 1 if nodes.size else 0
    if top <= 4 * nodes.size + n_items:  # mesh node numbers: one vertex per number
        b = n_items + nodes
        n = n_items + top
    else:  # sparse numbers: the numbers listed, renumbered
        used, local = np.unique(nodes, return_inverse=True)
        b = n_items + local.ravel()
        n = n_items + len(used)
    a = items
    root = np.arange(n)
    while True:
        ra, rb = root[a], root[b]
        joins = ra != rb
        if not joins.any():
            break
        lo, hi = np.minimum(ra[joins], rb[joins]), np.maximum(ra[joins], rb[joins])
        np.minimum.at(root, hi, lo)  # each root onto the smallest root it meets: no cycle forms
        while True:  # pointer jumping: every vertex to its root
            up = root[root]
            if np.array_equal(up, root):
                break
            root = up
    first, labels = np.unique(root[:n_items], return_inverse=True)
    return len(first), labels.ravel()


def _scipy_parts(items: np.ndarray, nodes: np.ndarray, n_items: int) -> tuple[int, np.ndarray]:
    """`item_parts` by scipy's breadth-first labelling (parts in the order of their first item)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    used, local = np.unique(nodes, return_inverse=True)
    n = n_items + len(used)
    g = coo_matrix((np.ones(items.size, np.int8), (items, n_items + local.ravel())), shape=(n, n))
    _, labels = connected_components(g, directed=False)
    first, part = np.unique(labels[:n_items], return_inverse=True)
    return len(first), part.ravel()
