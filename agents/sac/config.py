"""Hyperparameters of the SAC agent: `SACConfig()` is the algorithm's neutral defaults (Acme's SAC, none of
this project's additions); a training job keeps its own tuned values (the training command's main job
keeps the arm's)."""
import dataclasses
from typing import ClassVar, Optional, Tuple

import numpy as np


@dataclasses.dataclass(frozen=True)
class SACConfig:
    """Everything that changes what the agent computes.

    Fields that change the learning dynamics are part of the checkpoint
    fingerprint, so a checkpoint is never resumed under different settings.
    """

    # Defaults: Acme's SAC (agents/jax/sac/config.py and networks.py); where Acme has no such
    # field, the addition is off. SACConfig.paper_sac() is the paper's run of it.
    batch_size: int = 256
    learning_rate: float = 3e-4  # critics, actor and temperature alike
    discount: float = 0.99
    tau: float = 0.005  # Polyak rate of the target critics
    # The entropy the temperature steers the policy to: `target_entropy` if given, else
    # `target_entropy_per_action` x |A|. Acme's -1 per action leaves an exploration noise of about
    # 9 % of each action's half-range; -2 (about 3 %) suits tasks that need their actions right to
    # about 1 % (docs/log/learning.md#the-recipe-becomes-the-default-the-main-job-over-3-seeds-2026-11-30).
    target_entropy: Optional[float] = None
    target_entropy_per_action: float = -1.0
    # Acme starts at 1; on rewards of a few units per step that entropy bonus can outweigh the task
    # for most of a short run (the main job starts at 0.01 and lets the loss raise it).
    init_temperature: float = 1.0
    hidden_sizes: Tuple[int, ...] = (256, 256)
    min_replay_size: int = 10_000
    max_replay_size: int = 1_000_000
    # The learner runs `updates_per_call` gradient steps (one lax.scan) every
    # `env_steps_per_call` agent steps (transitions): update-to-data ratio = their quotient.
    updates_per_call: int = 1
    env_steps_per_call: int = 1
    # The agent acts every `action_repeat` control steps.
    action_repeat: int = 1
    reward_scale: float = 1.0
    log_std_min: float = -5.0
    log_std_max: float = 2.0
    # Agent improvements beyond the paper's SAC (off by default).
    critic_layer_norm: bool = False  # LayerNorm in every hidden layer of both critics
    # Hindsight relabelling (HER, "future" strategy) on tasks with the goal interface (agents/goals.py;
    # other tasks get none): this fraction of every sampled batch gets a goal reached later in the
    # same episode, with the reward recomputed exactly (a curriculum may name the lessons that get
    # it: agents/curriculum.LessonSettings; the task may limit the goals to those it could set).
    her_ratio: float = 0.0
    # Recompute every sampled transition's reward with the current lesson's reward function
    # (needs the same goal-aware tasks): after a lesson switch, lesson-1 transitions in the
    # replay then carry lesson-2 rewards instead of the ones they were collected with.
    relabel_rewards: bool = False
    # Weight of a penalty on the squared deterministic action in the actor loss (times the
    # critic's mean |Q|, as TD3+BC): keeps a residual policy (SACBuilder) at its base unless the critic
    # clearly prefers a correction (0 = off, plain SAC's actor loss; 0.4 is TD3+BC's alpha = 2.5).
    action_anchor: float = 0.0
    # Weight of a penalty on the squared pre-tanh mean of the policy in the actor loss (the
    # original SAC code's mean regulariser, 1e-3 there; 0 = off, plain SAC). An action whose
    # mean sits deep in the tanh's saturation gets almost no gradient from the critic (at 2.9:
    # 1 - tanh^2 = 0.012); this pulls it back where the critic can move it
    # (docs/log/learning.md, the section of 2026-12-01 on a penalty on the pre-tanh mean).
    pre_tanh_penalty: float = 0.0
    # Evaluate (and deploy) an exponential moving average of the policy's parameters, updated
    # with this rate after every gradient step (0 = off: the last policy, as the paper). The
    # agent still explores with its current policy, so training is unchanged bit for bit; the
    # average smooths the update-to-update wobble that moves a held-out target in or out of
    # the tolerance from one evaluation to the next: 1e-4 is about the last 10k updates
    # (docs/log/learning.md#snapshot-noise-a-longer-budget-and-a-moving-average-policy-2026-12-01).
    policy_average: float = 0.0
    # ... but early on, while 1 / policy_average is more updates than the run has made, the
    # average spans about this fraction of the updates so far (rate max(policy_average,
    # 1 / (1 + fraction * updates))) instead of keeping the initial policy's weight: a plain
    # EMA at 1e-4 leaves a short run's average mostly at the random initial policy; 0 = the
    # plain EMA.  From 100k updates on the rate is policy_average itself. It shapes the average
    # only: while policy_average is 0 there is none.
    policy_average_fraction: float = 0.1
    # Each observation entry also enters the networks as tanh(gain x entry) (0 = off, plain SAC): an
    # error observed in metres or radians is a few thousandths near its goal, where a precise task is
    # decided; at a gain of 100, 5 mm reads 0.46 instead of 0.005, so the networks need no large weights
    # to tell 5 mm from 10 mm.
    fine_input_gain: float = 0.0
    # The same for named observation entries only, each at its own gain: "key=gain" items, e.g.
    # ("to_target=100", "attitude_error=30") reads an error in metres at 100 and one in radians at
    # 30, so that 1 cm and 2 deg read about alike. Entries of order one would only be squashed to
    # their signs by a gain this high.
    fine_inputs: Tuple[str, ...] = ()

    # One line per field: what it sets (a training command's --help shows it beside the flag).
    HELP: ClassVar[dict] = {
        "batch_size": "transitions per gradient step",
        "learning_rate": "Adam step size of the critics, the actor and the temperature",
        "discount": "discount factor of the return",
        "tau": "Polyak rate at which the target critics follow the critics",
        "target_entropy": "entropy the temperature steers the policy to (overrides --target-entropy-per-action)",
        "target_entropy_per_action": "target entropy per action dimension (-1: Acme's; lower: narrower noise)",
        "init_temperature": "initial entropy temperature (alpha)",
        "hidden_sizes": "hidden layer widths of the actor and each critic, e.g. 64,64",
        "min_replay_size": "transitions collected before learning starts",
        "max_replay_size": "replay capacity in transitions (oldest dropped first)",
        "updates_per_call": "gradient steps per learner call (one jitted scan)",
        "env_steps_per_call": "agent steps between learner calls (update-to-data ratio: updates / steps)",
        "action_repeat": "control steps each action is held for",
        "reward_scale": "factor on every reward the learner sees",
        "log_std_min": "lower clip of the policy's log standard deviation",
        "log_std_max": "upper clip of the policy's log standard deviation",
        "critic_layer_norm": "LayerNorm in every hidden layer of both critics",
        "her_ratio": "share of each batch given a hindsight goal reached later in its episode (0: off)",
        "relabel_rewards": "recompute sampled rewards with the current lesson's reward function",
        "action_anchor": "weight of the actor-loss penalty that keeps a residual policy at its base (0: off)",
        "pre_tanh_penalty": "weight of the penalty on the policy's squared pre-tanh mean (0: off)",
        "policy_average": "rate of the moving average of the policy that is evaluated and deployed (0: off)",
        "policy_average_fraction": "early on, the average spans this fraction of the updates so far (0: plain average)",
        "fine_input_gain": "each observation entry also enters the networks as tanh(gain x entry) (0: off)",
        "fine_inputs": "observation entries that also enter as tanh(gain x entry), e.g. to_target=100 (none: off)",
    }

    # Upper bounds of the sizes (generous: far beyond any run measured; they keep a typo from
    # asking for days of updates or terabytes of replay).
    LIMITS: ClassVar[dict] = {"batch_size": 65_536, "updates_per_call": 1_000, "env_steps_per_call": 100_000,
                              "action_repeat": 1_000, "min_replay_size": 10_000_000,
                              "max_replay_size": 10_000_000}
    MAX_HIDDEN_LAYERS: ClassVar[int] = 16
    MAX_HIDDEN_SIZE: ClassVar[int] = 8_192

    def __post_init__(self):
        """Every field checked here, where it is owned: a bad value fails when the config is made
        (a training command names the flag), not as a NaN loss or a JAX error after training began."""
        for name, limit in self.LIMITS.items():
            value, low = getattr(self, name), 0 if name == "min_replay_size" else 1
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not low <= value <= limit:
                raise ValueError(f"{name} must be a whole number from {low} to {limit}, got {value!r}")
        hidden = tuple(self.hidden_sizes) if not isinstance(self.hidden_sizes, (str, int)) else None
        if (not hidden or len(hidden) > self.MAX_HIDDEN_LAYERS
                or not all(isinstance(h, (int, np.integer)) and 1 <= h <= self.MAX_HIDDEN_SIZE for h in hidden)):
            raise ValueError(f"hidden_sizes must be 1 to {self.MAX_HIDDEN_LAYERS} layer widths, each from 1 to "
                             f"{self.MAX_HIDDEN_SIZE}, e.g. 64,64; got {self.hidden_sizes!r}")
        for name, high in (("learning_rate", 1.0), ("init_temperature", 1e6), ("reward_scale", 1e6)):
            value = getattr(self, name)
            if not (np.isfinite(value) and 0 < value <= high):
                raise ValueError(f"{name} must be a number > 0 and at most {high:g}, got {value}")
        if not (np.isfinite(self.log_std_min) and np.isfinite(self.log_std_max)
                and -20 <= self.log_std_min < self.log_std_max <= 20):
            raise ValueError("log_std_min and log_std_max must be finite with -20 <= log_std_min < log_std_max "
                             f"<= 20, got {self.log_std_min} and {self.log_std_max}")
        if self.target_entropy is not None and not np.isfinite(self.target_entropy):
            raise ValueError(f"target_entropy must be finite (or None), got {self.target_entropy}")
        if not 0.0 < self.tau <= 1.0:
            raise ValueError(f"tau must be in (0, 1], got {self.tau}")
        if not 0.0 <= self.her_ratio <= 1.0:
            raise ValueError(f"her_ratio must be in [0, 1], got {self.her_ratio}")
        if not 0.0 < self.discount <= 1.0:
            raise ValueError(f"discount must be in (0, 1], got {self.discount}")
        if not np.isfinite(self.target_entropy_per_action):
            raise ValueError(f"target_entropy_per_action must be finite, got {self.target_entropy_per_action}")
        if not 0.0 <= self.policy_average < 1.0:
            raise ValueError(f"policy_average must be a rate in [0, 1) (0 = off), got {self.policy_average}")
        if not 0.0 <= self.policy_average_fraction <= 1.0:
            raise ValueError("policy_average_fraction must be in [0, 1] (0 = a plain moving average), "
                             f"got {self.policy_average_fraction}")
        if not (np.isfinite(self.fine_input_gain) and 0.0 <= self.fine_input_gain <= 1e6):
            raise ValueError(f"fine_input_gain must be a number from 0 (off) to 1e6, got {self.fine_input_gain}")
        items = self.fine_inputs.split(",") if isinstance(self.fine_inputs, str) else self.fine_inputs  # as the flag
        object.__setattr__(self, "fine_inputs", tuple(str(item).strip() for item in items if str(item).strip()))
        self.fine_input_gains()  # every item read, or the error names it
        if not (np.isfinite(self.pre_tanh_penalty) and self.pre_tanh_penalty >= 0):
            raise ValueError(f"pre_tanh_penalty must be a finite weight >= 0, got {self.pre_tanh_penalty}")
        if not (np.isfinite(self.action_anchor) and self.action_anchor >= 0):
            raise ValueError(f"action_anchor must be a finite weight >= 0, got {self.action_anchor}")
        if self.min_replay_size > self.max_replay_size:
            raise ValueError(f"min_replay_size {self.min_replay_size} exceeds max_replay_size {self.max_replay_size}")
        object.__setattr__(self, "hidden_sizes", tuple(int(h) for h in self.hidden_sizes))

    def fine_input_gains(self) -> dict:
        """``fine_inputs`` as {observation key: gain}; ValueError naming an item that is not
        key=gain with a gain from 0 (exclusive) to 1e6, or a key named twice."""
        gains = {}
        for item in self.fine_inputs:
            key, sep, text = item.partition("=")
            try:
                gain = float(text) if sep and key.strip() else None
            except ValueError:
                gain = None
            if gain is None or not (np.isfinite(gain) and 0.0 < gain <= 1e6):
                raise ValueError(f"fine_inputs: {item!r} is not key=gain with a gain above 0 and at most 1e6, "
                                 "e.g. to_target=100")
            if key.strip() in gains:
                raise ValueError(f"fine_inputs names {key.strip()!r} twice")
            gains[key.strip()] = gain
        return gains

    def fine_input_entries(self, keys, sizes) -> tuple:
        """((flat index, gain), ...) of ``fine_inputs`` in an observation of ``keys`` with ``sizes``
        (an ObservationFlattener's); ValueError naming a key the observation lacks."""
        gains = self.fine_input_gains()
        missing = sorted(set(gains) - set(keys or ()))
        if missing:
            raise ValueError(f"fine_inputs names {missing}, which the observation lacks "
                             f"(it has {list(keys) if keys else 'no named entries'})")
        entries, start = [], 0
        for key, size in zip(keys or (), sizes):
            entries += [(start + i, gains[key]) for i in range(size)] if key in gains else []
            start += size
        return tuple(entries)

    @property
    def update_to_data_ratio(self) -> float:
        return self.updates_per_call / self.env_steps_per_call

    def resolved_target_entropy(self, action_size: int) -> float:
        if self.target_entropy is not None:
            return float(self.target_entropy)
        return self.target_entropy_per_action * float(action_size)

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["hidden_sizes"], d["fine_inputs"] = list(self.hidden_sizes), list(self.fine_inputs)
        return d

    @classmethod
    def paper_sac(cls, **overrides) -> "SACConfig":
        """Plain SAC as the paper and Acme run it: the defaults (batch 256, 256x256, lr 3e-4, initial
        temperature 1, 10k random transitions first, one decision per control step, one update per
        transition, none of this project's additions), the learner called every 8 transitions
        with 8 updates (the same ratio, in fewer calls)."""
        return cls(**{"updates_per_call": 8, "env_steps_per_call": 8, **overrides})

    @property
    def uses_goals(self) -> bool:
        """Whether the replay must keep achieved goals (for HER or reward recomputation)."""
        return self.her_ratio > 0.0 or self.relabel_rewards

    # Fields that configs written before 2026-12-05 hold and SACConfig no longer has, with the value
    # that means what it now does without them: her_level_goals (hindsight goals only among those
    # the task could set) is the reaching tasks' option hindsight_level_goals now.
    REMOVED_FIELDS: ClassVar[dict] = {"her_level_goals": False}
    # Fields added since, with the value that computes what configs written before them computed:
    # a stored config without one reads as holding it.
    ADDED_FIELDS: ClassVar[dict] = {"fine_input_gain": 0.0, "fine_inputs": []}  # as JSON holds them

    @classmethod
    def from_dict(cls, d: dict) -> "SACConfig":
        """The config a dict (a checkpoint's, config.json's) holds; a removed field is dropped where
        it holds the value that now goes without saying, refused (ValueError) otherwise."""
        changed = {k: d[k] for k in cls.REMOVED_FIELDS if k in d and d[k] != cls.REMOVED_FIELDS[k]}
        if changed:
            raise ValueError(f"SACConfig no longer has {changed} (REMOVED_FIELDS says where it went)")
        d = {k: v for k, v in d.items() if k not in cls.REMOVED_FIELDS}
        fields = {f.name for f in dataclasses.fields(cls)}
        unknown = set(d) - fields
        if unknown:
            raise ValueError(f"unknown SACConfig fields: {sorted(unknown)}")
        d = {**d, **{k: tuple(d[k]) for k in ("hidden_sizes", "fine_inputs") if k in d}}
        return cls(**d)
