"""Trained policies that ship with the package, run with numpy alone: no training, no JAX.

A policy file (``.npz``) holds what acting needs and nothing else: the actor's layers
(a ReLU MLP and the mean head; the action is ``tanh`` of the mean, mapped onto the
action bounds), the observation layout it reads (keys and sizes, in order), the action
bounds, the model fingerprint of the robot it was trained on, and how it was trained
(command, seed, task, layout). :func:`load_policy` gives a callable: a dm_env timestep
(or an observation dict) in, the environment's action out.

    env = robostrich_suite.load("robostrich", "track")
    policy = robostrich_suite.load_policy("robostrich", env)   # refuses another robot
    timestep = env.reset()
    while not timestep.last():
        timestep = env.step(policy(timestep))
"""
from __future__ import annotations

import dataclasses
import functools
import json
import pathlib
import zipfile
import zlib

import numpy as np

from robostrich_suite import atomic_files
from robostrich_suite import fingerprint as fingerprint_lib
from robostrich_suite import input_files, parsing

FORMAT_VERSION = 1
MAX_POLICY_BYTES = 64 << 20  # a policy file, packed or unpacked: the shipped ones are tens of kB
POLICY_DIR = pathlib.Path(__file__).parent / "data" / "policies"
# The shipped policies by name (a domain's default robot and task family).
SHIPPED = {"robostrich": POLICY_DIR / "robostrich_curriculum.npz",  # the arm on its frame
           "robostrich_a1": POLICY_DIR / "robostrich_a1_curriculum.npz",  # on the quadruped, after lesson 4
           # the arm on its frame, trained with a control step of latency drawn per episode
           "robostrich_robust": POLICY_DIR / "robostrich_robust.npz"}


class PolicyMismatch(ValueError):
    """A policy asked to act in an environment it was not trained for."""


@dataclasses.dataclass(frozen=True)
class Policy:
    """A deterministic tanh-Gaussian policy's mean, as trained (the moving average of its
    parameters, which evaluations use)."""

    hidden: tuple  # ((w, b), ...): ReLU layers
    mean: tuple  # (w, b): the mean head, squashed by tanh into [-1, 1]
    observation_layout: tuple  # ((key, size), ...) in the order the network reads them
    action_low: np.ndarray
    action_high: np.ndarray
    fingerprint: str  # compiled_fingerprint of the environment's model it was trained in
    info: dict  # how it was made: command, seed, domain, task, layout, run fingerprint
    # The network also reads tanh(gain x observation) after the observation (0: the observation alone),
    # as the policy was trained (fine inputs: a few millimetres of error read as a large input).
    fine_input_gain: float = 0.0
    # ((observation key, gain), ...): those entries also read as tanh(gain x entry), after the above.
    fine_inputs: tuple = ()

    @property
    def observation_size(self) -> int:
        return int(sum(size for _, size in self.observation_layout))

    def flatten(self, observation) -> np.ndarray:
        """The observation dict as one vector, in the layout the network reads."""
        try:
            parts = [np.asarray(observation[key], np.float32).ravel() for key, _ in self.observation_layout]
        except KeyError as error:
            raise PolicyMismatch(f"the observation has no {error.args[0]!r}, which this policy reads") from None
        flat = np.concatenate(parts)
        if flat.size != self.observation_size:
            raise PolicyMismatch(f"observation of size {flat.size}, this policy reads {self.observation_size}")
        return flat

    def select_action(self, flat_observation) -> np.ndarray:
        """The environment action for a flattened observation (agents' actor interface)."""
        h = np.asarray(flat_observation, np.float32)
        parts = [h]
        if self.fine_input_gain:
            parts.append(np.tanh(np.float32(self.fine_input_gain) * h))
        if self.fine_inputs:
            index, gains = self._fine_entries
            parts.append(np.tanh(h[index] * gains))
        h = np.concatenate(parts) if len(parts) > 1 else h
        for w, b in self.hidden:
            h = np.maximum(h @ w + b, 0.0)
        squashed = np.tanh(h @ self.mean[0] + self.mean[1]).astype(np.float64)
        return self.action_low + 0.5 * (squashed + 1.0) * (self.action_high - self.action_low)

    @functools.cached_property
    def _fine_entries(self):
        """(flat indices, gains) of ``fine_inputs`` in the observation layout, in its order."""
        gains, index, weights, start = dict(self.fine_inputs), [], [], 0
        for key, size in self.observation_layout:
            if key in gains:
                index += range(start, start + size)
                weights += [gains[key]] * size
            start += size
        return np.array(index, np.int64), np.array(weights, np.float32)

    @property
    def input_size(self) -> int:
        """What the first layer reads: the observation, and its fine inputs."""
        return (self.observation_size * (2 if self.fine_input_gain else 1)
                + (self._fine_entries[0].size if self.fine_inputs else 0))

    def __call__(self, timestep_or_observation) -> np.ndarray:
        observation = getattr(timestep_or_observation, "observation", timestep_or_observation)
        return self.select_action(self.flatten(observation))

    def task_kwargs(self) -> dict:
        """The task options this policy's observation needs (``observe_sent_actions``), {} for most."""
        sent = self.info.get("observe_sent_actions")
        return {"observe_sent_actions": int(sent)} if sent else {}

    def check(self, env) -> None:
        """PolicyMismatch (one line) unless ``env`` is the robot this policy was trained on,
        observes what it reads and takes the actions it gives."""
        found = fingerprint_lib.compiled_fingerprint(env.physics.model)
        if found != self.fingerprint:
            raise PolicyMismatch(f"this policy was trained on model {self.fingerprint} "
                                 f"({self.info.get('domain', '?')}, layout {self.info.get('layout', '?')}); "
                                 f"the environment's model is {found}")
        observed = {key: int(np.prod(spec.shape)) for key, spec in env.observation_spec().items()}
        wrong = [key for key, size in self.observation_layout if observed.get(key) != size]
        if wrong:  # a task may observe more (track: its target index) than the policy reads
            hint = (f"; load the task with task_kwargs={self.task_kwargs()}" if self.task_kwargs() else "")
            raise PolicyMismatch(f"this policy reads {wrong}, which the environment does not observe "
                                 f"with the same sizes ({observed}){hint}")
        spec = env.action_spec()
        if not (np.allclose(spec.minimum, self.action_low) and np.allclose(spec.maximum, self.action_high)):
            raise PolicyMismatch("the environment's action bounds differ from the policy's")

    def save(self, path) -> None:
        """Write the policy file (beside it first, then renamed: never half-written)."""
        path = pathlib.Path(path)
        arrays = {f"hidden_{i}_{part}": a for i, layer in enumerate(self.hidden) for part, a in zip("wb", layer)}
        arrays.update(mean_w=self.mean[0], mean_b=self.mean[1], action_low=self.action_low,
                      action_high=self.action_high)
        meta = {"format_version": FORMAT_VERSION, "fingerprint": self.fingerprint,
                "observation_layout": [list(item) for item in self.observation_layout], "info": self.info,
                "fine_input_gain": self.fine_input_gain, "fine_inputs": [[k, g] for k, g in self.fine_inputs]}
        with atomic_files.replaced_atomically(path) as f:
            np.savez_compressed(f, meta=np.array(json.dumps(meta)), **arrays)


def read_policy(path) -> Policy:
    """The policy in ``path``; ValueError naming the file if it is not a policy file of
    the version this code reads."""
    path = pathlib.Path(path)
    try:
        archive = input_files.npz_bytes(path, MAX_POLICY_BYTES, MAX_POLICY_BYTES, "policy file")
        with np.load(archive, allow_pickle=False) as data:
            meta = _metadata(path, data["meta"])
            count = sum(1 for key in data.files if key.startswith("hidden_") and key.endswith("_w"))
            hidden = tuple((data[f"hidden_{i}_w"], data[f"hidden_{i}_b"]) for i in range(count))
            policy = Policy(hidden=hidden, mean=(data["mean_w"], data["mean_b"]),
                            observation_layout=_observation_layout(path, meta["observation_layout"]),
                            action_low=data["action_low"].astype(np.float64),
                            action_high=data["action_high"].astype(np.float64),
                            fingerprint=str(meta["fingerprint"]), info=dict(meta.get("info", {})),
                            fine_input_gain=_fine_input_gain(path, meta.get("fine_input_gain", 0.0)),
                            fine_inputs=_fine_inputs(path, meta.get("fine_inputs", []), meta["observation_layout"]))
    except FileNotFoundError:
        raise ValueError(f"{path}: no such policy file") from None
    except (KeyError, OSError, EOFError, zipfile.BadZipFile, zlib.error, TypeError, AttributeError) as error:
        raise ValueError(f"{path}: not a policy file ({type(error).__name__}: {error})") from None
    check_arrays(policy, path)
    return policy


def _metadata(path, stored) -> dict:
    """The policy file's metadata (JSON), of the format version this code reads."""
    try:
        meta = parsing.loads_json(str(stored))
    except ValueError as error:
        raise ValueError(f"{path}: not a policy file (its metadata: {error})") from None
    if not isinstance(meta, dict):
        raise ValueError(f"{path}: not a policy file (its metadata is a JSON {type(meta).__name__}, not an object)")
    version = meta.get("format_version")
    if version != FORMAT_VERSION:
        raise ValueError(f"{path}: policy file format {version!r}, this code reads format {FORMAT_VERSION}")
    if not isinstance(meta.get("fingerprint"), str) or not isinstance(meta.get("info", {}), dict):
        raise ValueError(f"{path}: not a policy file (its metadata lacks the model fingerprint, a string, or "
                         "holds an 'info' that is not an object)")
    return meta


def _fine_input_gain(path, gain) -> float:
    """The metadata's fine_input_gain: a finite number >= 0 (absent in files of policies trained without it)."""
    if isinstance(gain, bool) or not isinstance(gain, (int, float)) or not (np.isfinite(gain) and gain >= 0):
        raise ValueError(f"{path}: not a policy file (its fine_input_gain {gain!r} is not a number >= 0)")
    return float(gain)


def _fine_inputs(path, items, layout) -> tuple:
    """The metadata's fine_inputs: [[observation key, gain > 0], ...], each key one the policy reads
    (absent in files of policies trained without them)."""
    keys = {key for key, _ in layout}
    try:
        pairs = tuple((key, float(gain)) for key, gain in items
                      if isinstance(key, str) and not isinstance(gain, (bool, str)))
    except (TypeError, ValueError):
        pairs = None
    if pairs is None or len(pairs) != len(items) or len({k for k, _ in pairs}) != len(pairs) or not all(
            k in keys and np.isfinite(g) and g > 0 for k, g in pairs):
        raise ValueError(f"{path}: not a policy file (its fine_inputs {items!r} are not [[key, gain > 0], ...] "
                         "over keys of its observation layout, each once)")
    return pairs


def _observation_layout(path, layout) -> tuple:
    """((key, size), ...) from the metadata: keys named, sizes whole and positive."""
    try:
        pairs = tuple((key, size) for key, size in layout)
    except (TypeError, ValueError):
        pairs = None
    if (not pairs or not all(isinstance(k, str) and isinstance(s, int) and not isinstance(s, bool) and 0 < s < 2**20
                             for k, s in pairs)):
        raise ValueError(f"{path}: not a policy file (its observation layout is not [[key, size], ...] "
                         f"with positive sizes)")
    return pairs


def check_arrays(policy: Policy, path) -> None:
    """ValueError naming ``path`` unless the layers chain from the observation's size to the
    action's, and every number is finite: a wrong shape would fail in numpy's matmul with
    nothing about the file, NaN weights in the first step of an evaluation."""
    arrays = [(f"hidden_{i}_{part}", a) for i, layer in enumerate(policy.hidden) for part, a in zip("wb", layer)]
    arrays += [("mean_w", policy.mean[0]), ("mean_b", policy.mean[1]),
               ("action_low", policy.action_low), ("action_high", policy.action_high)]
    for name, array in arrays:
        if array.dtype.kind != "f":
            raise ValueError(f"{path}: {name} holds {array.dtype} values, not floating-point weights")
        if not np.all(np.isfinite(array)):
            raise ValueError(f"{path}: {name} holds non-finite values (NaN or inf): not a usable policy")
    if policy.action_low.ndim != 1:
        raise ValueError(f"{path}: action_low has shape {policy.action_low.shape}, expected (n,): one bound per action")
    width = policy.input_size  # what the next layer reads
    actions = policy.action_low.shape[0]
    expected = {}
    for i, _ in enumerate(policy.hidden):
        out = policy.hidden[i][0].shape[-1] if policy.hidden[i][0].ndim == 2 else None
        expected[f"hidden_{i}_w"], expected[f"hidden_{i}_b"] = (width, out), (out,)
        width = out
    expected.update(mean_w=(width, actions), mean_b=(actions,), action_low=(actions,), action_high=(actions,))
    for name, array in arrays:
        if None in expected[name] or array.shape != expected[name]:
            fine = policy.input_size - policy.observation_size
            reads = (f" (the observation layout reads {policy.observation_size} values"
                     f"{f', and {fine} fine inputs' if fine else ''})" if name == "hidden_0_w" else "")
            raise ValueError(f"{path}: {name} has shape {array.shape}, expected {_shape(expected[name])}{reads}")
    if not np.all(policy.action_low < policy.action_high):
        raise ValueError(f"{path}: action_low must lie below action_high for every action")


def _shape(shape: tuple) -> str:
    return "(" + ", ".join("n" if n is None else str(n) for n in shape) + ("," if len(shape) == 1 else "") + ")"


def load_policy(name_or_path: str = "robostrich", env=None) -> Policy:
    """A shipped policy by name (``SHIPPED``) or a policy file by path; with ``env``,
    checked against it (:meth:`Policy.check`)."""
    path = SHIPPED.get(name_or_path)
    if path is None:
        path = pathlib.Path(name_or_path)
        if path.suffix != ".npz":
            raise ValueError(f"unknown policy {name_or_path!r}: a shipped one ({', '.join(SHIPPED)}) "
                             f"or a .npz policy file")
    policy = read_policy(path)
    if env is not None:
        policy.check(env)
    return policy
