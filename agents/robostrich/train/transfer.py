"""Start a run's learner from a checkpoint of another domain (``robostrich-train --init-from``).

The a1 curriculum (the arm on the quadruped) can start from an agent trained on the
immobile arm (``robostrich``), although the observations differ: the a1 has the trunk's
motion, a sideways component, and positions in the trunk frame.  The learner's
parameters are mapped input by input:

* an :class:`ObservationMap` says, for each entry of the new domain's flat observation,
  which entry of the checkpoint's it equals (plus a constant offset) or that it is new.
  Both layouts are the real flatteners' (the checkpoint's fingerprint has the one that
  trained it, the new run's comes from its environment's spec); which a1 component is
  which frame component, and the offset, are data beside ``frame_to_trunk``
  (``quadruped_tasks.FRAME_OBSERVATION_SOURCES``);
* every first layer that reads observations (the policy, both critics and both target
  critics; a critic reads ``[obs, action]``) gets the source's rows for mapped inputs and
  zero rows for new ones, and its bias absorbs the offsets (``b' = b - offset @ W'``), so
  the new networks compute exactly what the old ones did on corresponding states;
* Adam's moment estimates are mapped the same way (zeros for new rows), the temperature
  and its optimiser are copied; the RNG key and update counter are the new run's own.

The replay is not carried (its transitions have the other domain's observations).  The
same domain with the same layout is a plain copy of the learner.
"""
import dataclasses
import os
from typing import Dict, Mapping, Optional, Sequence, Tuple

import jax
import numpy as np
from jax.flatten_util import ravel_pytree

from agents import checkpoint, trees
from agents.robostrich.run_spec import migrate, named_layout, parse_plan
from agents.robostrich.train.main_job import MAIN_JOB_SAC
from agents.sac import state_layout
from agents.sac.config import SACConfig
from robostrich_suite.tasks import quadruped_tasks as qt

# Config fields that make two networks different functions of their inputs.
NETWORK_FIELDS = ("hidden_sizes", "critic_layer_norm", "log_std_min", "log_std_max")


class TransferError(ValueError):
    """A checkpoint that cannot start this run."""


def correspondence(source_domain: str, target_domain: str) -> Tuple[Mapping, Mapping]:
    """(sources, shifts) of ObservationMap.between for a domain pair; TransferError if unsupported."""
    if source_domain == target_domain:
        return {}, {}
    if (source_domain, target_domain) == ("robostrich", "robostrich_a1"):
        return qt.FRAME_OBSERVATION_SOURCES, {k: qt.FRAME_TO_TRUNK_OFFSET for k in qt.FRAME_POSITION_KEYS}
    raise TransferError(f"--init-from: a checkpoint of {source_domain!r} cannot start a run on {target_domain!r} "
                        "(supported: the same domain, or robostrich -> robostrich_a1)")


@dataclasses.dataclass(frozen=True)
class ObservationMap:
    """target_obs[i] = source_obs[index[i]] + offset[i] where index[i] >= 0; index -1: a new input."""

    source_size: int
    index: np.ndarray
    offset: np.ndarray

    @property
    def target_size(self) -> int:
        return len(self.index)

    @property
    def new_inputs(self) -> np.ndarray:
        return np.flatnonzero(self.index < 0)

    @classmethod
    def between(cls, source_layout: Sequence, target_layout: Sequence, sources: Optional[Mapping] = None,
                shifts: Optional[Mapping] = None) -> "ObservationMap":
        """Layouts: [[key, size], ...] in flat order (ObservationFlattener.describe).  ``sources``: per target
        key, a (source key, component) or None per component (keys not listed: the source's key, component by
        component); ``shifts``: per source key, what its components gain on the way (default 0)."""
        sources, shifts = dict(sources or {}), dict(shifts or {})
        starts, sizes, position = {}, {}, 0
        for key, size in source_layout:
            starts[key], sizes[key] = position, int(size)
            position += int(size)
        index, offset = [], []
        for key, size in target_layout:
            spec = sources.get(key)
            if spec is None:
                if sizes.get(key) != int(size):
                    found = "missing" if key not in sizes else f"of size {sizes[key]}"
                    raise TransferError(f"--init-from: observation {key!r} (size {size}) of this run is {found} "
                                        "in the checkpoint's observations")
                spec = [(key, c) for c in range(int(size))]
            if len(spec) != int(size):
                raise TransferError(f"observation {key!r} has {size} components, its correspondence names {len(spec)}")
            for component in spec:
                if component is None:
                    index.append(-1)
                    offset.append(0.0)
                    continue
                source_key, c = component
                if source_key not in sizes or not 0 <= c < sizes[source_key]:
                    raise TransferError(f"observation {key!r} reads {source_key!r}[{c}], which the checkpoint's "
                                        "observations do not have")
                index.append(starts[source_key] + c)
                offset.append(float(np.asarray(shifts.get(source_key, np.zeros(sizes[source_key])))[c]))
        index = np.asarray(index, np.int64)
        used = np.bincount(index[index >= 0], minlength=position)
        if np.any(used != 1):  # an unread (or twice read) input: the networks could not compute the same
            keys = sorted({key for key, size in source_layout
                           if np.any(used[starts[key]:starts[key] + int(size)] != 1)})
            raise TransferError(f"--init-from: the checkpoint's observations {keys} have no one counterpart "
                                "in this run's")
        return cls(position, index, np.asarray(offset, np.float64))

    def __call__(self, source_obs) -> np.ndarray:
        """The target observation of a source observation (new inputs 0); for checks and tests."""
        source_obs = np.asarray(source_obs, np.float64)
        out = np.zeros(source_obs.shape[:-1] + (self.target_size,))
        mapped = self.index >= 0
        out[..., mapped] = source_obs[..., self.index[mapped]] + self.offset[mapped]
        return out


# -- parameters and optimiser states ---------------------------------------------------------------
def _is_first_layer(module: str) -> bool:
    """haiku's MLP 'policy_torso/~/linear_0', 'critic/~/linear_0'; the layer-normed critic's 'critic_linear_0'."""
    return module.endswith("linear_0")


def map_params(params: Mapping, obs_map: ObservationMap, moments: bool = False) -> Dict:
    """The parameters (or, ``moments``, an optimiser's per-parameter moments) for the target inputs.

    First layers' weights (the twin critics' stacked on a leading axis): rows of mapped inputs
    copied, new inputs' rows zero, rows past the observation (a critic's action) copied; biases
    absorb the offsets (not for moments)."""
    out = {}
    for module, leaves in params.items():
        leaves = dict(leaves)
        if _is_first_layer(module):
            w = np.asarray(leaves["w"])
            extra = w.shape[-2] - obs_map.source_size  # the critic's action inputs
            if extra < 0:
                raise TransferError(f"layer {module!r} reads {w.shape[-2]} inputs, fewer than the checkpoint's "
                                    f"{obs_map.source_size} observations")
            mapped = obs_map.index >= 0
            new_w = np.zeros(w.shape[:-2] + (obs_map.target_size + extra, w.shape[-1]), w.dtype)
            new_w[..., np.flatnonzero(mapped), :] = w[..., obs_map.index[mapped], :]
            new_w[..., obs_map.target_size:, :] = w[..., obs_map.source_size:, :]
            if not moments:
                b = np.asarray(leaves["b"], np.float64)
                rows = new_w[..., :obs_map.target_size, :].astype(np.float64)
                shift = np.einsum("i,...io->...o", obs_map.offset, rows)  # offset @ W', per critic of a pair
                leaves["b"] = (b - shift).astype(np.asarray(leaves["b"]).dtype)
            leaves["w"] = new_w
        out[module] = leaves
    return out


def map_opt_state(opt_state, params: Mapping, obs_map: ObservationMap):
    """An optax state with Adam's moments (one vector per parameter group) mapped as the parameters are."""
    size = sum(np.size(leaf) for leaf in jax.tree_util.tree_leaves(params))
    if isinstance(opt_state, np.ndarray) and opt_state.ndim == 1 and opt_state.size == size > 1:
        moments = ravel_pytree(params)[1](opt_state)  # optax.flatten's order: the tree's leaves
        return np.asarray(ravel_pytree(map_params(moments, obs_map, moments=True))[0])
    if isinstance(opt_state, tuple):
        children = [map_opt_state(child, params, obs_map) for child in opt_state]
        return type(opt_state)(*children) if hasattr(opt_state, "_fields") else tuple(children)
    return opt_state


def stored_learner(arrays, fresh, path: str):
    """The learner state a checkpoint stores (agents/trees.py) on the structure of ``fresh``, this
    run's learner state, with a policy average where the checkpoint kept one and none where it
    kept none; the first layers keep the checkpoint's shapes for :func:`transfer_state` to map."""
    averaged = isinstance(arrays, dict) and any(p.startswith(".average_policy_params") for p in arrays)
    like = fresh._replace(average_policy_params=fresh.policy_params if averaged else None)
    try:
        return trees.rebuild(state_layout.upgrade(arrays), like, f"the learner of {path}")
    except ValueError as error:
        raise TransferError(f"--init-from: {error}") from None


def transfer_state(source, fresh, obs_map: ObservationMap):
    """A TrainingState for the target: `source`'s networks, optimisers and temperature mapped, `fresh`'s
    RNG key and update counter (both TrainingStates, numpy leaves). A target that keeps a policy
    average starts it from the source's average, or from its policy where it kept none."""
    source_average = getattr(source, "average_policy_params", None)
    average = None if fresh.average_policy_params is None else map_params(
        source.policy_params if source_average is None else source_average, obs_map)
    return fresh._replace(
        average_policy_params=average,
        policy_params=map_params(source.policy_params, obs_map),
        q_params=map_params(source.q_params, obs_map),
        target_q_params=map_params(source.target_q_params, obs_map),
        policy_opt_state=map_opt_state(source.policy_opt_state, source.policy_params, obs_map),
        q_opt_state=map_opt_state(source.q_opt_state, source.q_params, obs_map),
        log_alpha=np.asarray(source.log_alpha),
        alpha_opt_state=source.alpha_opt_state,
    )


# -- checkpoints -----------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class InitSource:
    """A checked --init-from checkpoint: where, its content hash (the sha256 of its payload, which the
    new run's fingerprint records as ``init_from``), its domain and fingerprint."""

    path: str
    digest: str
    domain: str
    fingerprint: dict


def _read(path: str):
    if not os.path.isfile(path):
        raise FileNotFoundError(f"--init-from: no checkpoint file {path}")
    return checkpoint.read_with_digest(path)  # checks header, checksum and format


def _single_domain(plan, what: str) -> str:
    domains = sorted({lesson.domain for lesson in plan})
    if len(domains) != 1:
        raise TransferError(f"--init-from: {what} spans several domains {domains}")
    return domains[0]


def check_source(path: str, plan, config: SACConfig, layout: Optional[str] = None, record=None,
                 residual_scale: float = 0.0) -> InitSource:
    """Everything that can be checked before building the run: a readable checkpoint, of a domain that can
    start `plan`'s, with the same tendon layout and networks.  TransferError (FileNotFoundError) otherwise."""
    if record is None:
        record, digest = _read(path)
    else:
        record, digest = record
    fingerprint = migrate(record["fingerprint"])
    missing = [k for k in ("plan", "config", "observation_layout", "action_size") if k not in fingerprint]
    missing += [k for k in ("learner",) if k not in record["payload"]]
    if missing:
        raise TransferError(f"--init-from: {path} is not a robostrich-train checkpoint (no {', '.join(missing)})")
    source_domain = _single_domain(parse_plan(fingerprint["plan"]), f"the plan of {path}")
    target_domain = _single_domain(plan, "this run's plan")
    correspondence(source_domain, target_domain)
    source_layout = fingerprint.get("layout")
    layout = named_layout(layout, plan)
    if source_layout != layout:
        raise TransferError(f"--init-from: {path} was trained with tendon layout {source_layout!r}, "
                            f"this run uses {layout!r} (pass --layout {source_layout})")
    for field in NETWORK_FIELDS:  # read from the dict: another run's config may have other fields, and
        # one without the field ran robostrich-train's value of then (the main job's: SACConfig's defaults until 2026-12-05)
        a, b = fingerprint["config"].get(field, getattr(MAIN_JOB_SAC, field)), getattr(config, field)
        a = tuple(a) if isinstance(a, list) else a
        if a != b:
            raise TransferError(f"--init-from: {path} has other networks: its {field} is {a}, this run's {b}")
    if fingerprint.get("residual_scale", 0.0) != residual_scale:
        raise TransferError(f"--init-from: {path} has residual_scale {fingerprint.get('residual_scale', 0.0)}, "
                            f"this run {residual_scale}")
    return InitSource(os.path.abspath(path), digest, source_domain, fingerprint)


def initialize(run, path: str, digest: Optional[str] = None) -> InitSource:
    """Start `run` (a fresh DomainRun) from the checkpoint at `path` (module doc) and record the
    checkpoint's content hash as the run's ``init_from``; `digest`: the hash the run was set up with
    (robostrich-train checks the file first), TransferError if the file has changed since."""
    record, found = _read(path)
    if digest is not None and found != digest:
        raise TransferError(f"--init-from: {path} has changed since this run was set up from it")
    source = check_source(path, run.plan, run.config, run.layout, record=(record, found),
                          residual_scale=run.residual_scale)
    if source.fingerprint["action_size"] != run.loop.actor.adapter.size:
        raise TransferError(f"--init-from: {path} acts with {source.fingerprint['action_size']} actions, "
                            f"this run with {run.loop.actor.adapter.size}")
    target_domain = _single_domain(run.plan, "this run's plan")
    obs_map = ObservationMap.between(source.fingerprint["observation_layout"], run.loop.flattener.describe(),
                                     *correspondence(source.domain, target_domain))
    learner = run.loop.learner
    fresh = learner.get_state()
    learner.set_state(transfer_state(stored_learner(record["payload"]["learner"], fresh, path), fresh, obs_map))
    run.loop.actor.update(learner.policy_params)
    # into the run's fingerprint: a resume knows where it started
    run.spec = dataclasses.replace(run.spec, init_from=source.digest)
    return source
