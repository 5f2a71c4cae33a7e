"""Pytrees (haiku parameters, optax states, the learner's state) as named arrays, for checkpoints.

A tree is stored as {path: array}, its paths as ``jax.tree_util.keystr`` writes them, and
rebuilt on the structure of a live tree of the same kind: the node types (dicts, tuples,
optax's named tuples) come from the running code, never from the file.
"""
import jax
import numpy as np


def to_arrays(tree) -> dict:
    """{path: numpy array} of ``tree``'s leaves, in its leaf order (a None subtree has none)."""
    leaves = jax.tree_util.tree_flatten_with_path(tree)[0]
    return {jax.tree_util.keystr(path): np.asarray(leaf) for path, leaf in leaves}


def rebuild(arrays, like, what: str = "tree"):
    """``like``'s structure with the leaves of ``arrays`` (from :func:`to_arrays`); ValueError
    naming ``what`` and a path where they differ. Shapes are left to the caller (a learner
    checks them; a transfer maps them)."""
    if not isinstance(arrays, dict):
        raise ValueError(f"{what} is not a table of arrays")
    leaves, structure = jax.tree_util.tree_flatten_with_path(like)
    paths = [jax.tree_util.keystr(path) for path, _ in leaves]
    missing = [p for p in paths if p not in arrays]
    extra = [p for p in arrays if p not in set(paths)]
    if missing or extra:
        differences = ([f"it lacks {len(missing)} arrays this one has (e.g. {missing[0]})"] if missing else []) + \
                      ([f"it has {len(extra)} arrays this one lacks (e.g. {extra[0]})"] if extra else [])
        raise ValueError(f"{what} does not match this one's structure: {'; '.join(differences)}")
    stored = [arrays[p] for p in paths]
    bad = [p for p, leaf in zip(paths, stored) if not isinstance(leaf, np.ndarray)]
    if bad:
        raise ValueError(f"{what} holds no array at {bad[0]}")
    return jax.tree_util.tree_unflatten(structure, stored)
