"""Connected parts through shared nodes (fepost.components.item_parts) against scipy's
connected_components on the same bipartite graphs: the same count and, after scipy's
labels are renumbered in order of first appearance, the same labels."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from fepost import components
from fepost.components import item_parts
from fepost.errors import ArgumentError


def scipy_parts(items, nodes, n_items):
    used, local = np.unique(nodes, return_inverse=True)
    n = n_items + len(used)
    g = coo_matrix((np.ones(len(items), np.int8), (items, n_items + local.ravel())), shape=(n, n))
    _, labels = connected_components(g, directed=False)
    first, lab = np.unique(labels[:n_items], return_inverse=True)
    return len(first), lab.ravel()


@pytest.mark.parametrize("seed", range(12))
def test_parts_equal_scipys(seed):
    """Random sparse graphs: many small parts, a few large ones, isolated items, repeats."""
    rng = np.random.default_rng(seed)
    n_items = int(rng.integers(1, 3000))
    k = int(rng.integers(0, 4 * n_items))
    items = rng.integers(0, n_items, k)
    nodes = rng.integers(0, int(rng.integers(1, 5 * n_items + 2)), k) * 7 + 3  # sparse node numbers
    count, labels = item_parts(items, nodes, n_items)
    ref_count, ref = scipy_parts(items, nodes, n_items)
    assert count == ref_count
    np.testing.assert_array_equal(labels, ref)


def test_a_long_chain_is_one_part():
    """A strip of 20 000 elements, each sharing a node with the next (worst case for
    propagation along the chain), listed in scrambled order."""
    n = 20_000
    items = np.repeat(np.arange(n), 2)
    nodes = (items + np.tile([0, 1], n)).astype(np.int64)
    perm = np.random.default_rng(1).permutation(n)
    count, labels = item_parts(perm[items], nodes, n)
    assert count == 1 and not labels.any()


def test_two_blocks_of_hexahedra_and_a_lonely_item():
    # two 2x1x1 blocks of hexahedra apart, element 4 lists nothing
    a = np.array([[0, 1, 4, 3, 6, 7, 10, 9], [1, 2, 5, 4, 7, 8, 11, 10]])
    b = a + 100
    conn = np.vstack([a, b[:1], b[1:]])
    items = np.repeat(np.arange(4), 8)
    count, labels = item_parts(items, conn.ravel(), 5)
    assert count == 3
    np.testing.assert_array_equal(labels, [0, 0, 1, 1, 2])


def test_bad_arguments_are_named():
    with pytest.raises(ArgumentError, match="one length"):
        item_parts([0, 1], [0], 2)
    with pytest.raises(ArgumentError, match=r"\[0, n_items\)"):
        item_parts([0, 2], [0, 1], 2)


@pytest.mark.parametrize("seed", range(4))
def test_scipy_path_for_large_graphs_labels_alike(monkeypatch, seed):
    rng = np.random.default_rng(100 + seed)
    n_items = 2000
    items = rng.integers(0, n_items, 3000)
    nodes = rng.integers(0, 4000, 3000)
    own = item_parts(items, nodes, n_items)
    monkeypatch.setattr(components, "SCIPY_FROM", 10)
    big = item_parts(items, nodes, n_items)
    assert own[0] == big[0]
    np.testing.assert_array_equal(own[1], big[1])
