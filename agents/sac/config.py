"""Hyperparameters of the SAC agent (Acme's defaults unless noted)."""
import dataclasses
from typing import Optional, Tuple


@dataclasses.dataclass(frozen=True)
class SACConfig:
    """Everything that changes what the agent computes.

    Fields that change the learning dynamics are part of the checkpoint
    fingerprint, so a checkpoint is never resumed under different settings.
    """

    batch_size: int = 256
    learning_rate: float = 3e-4  # critics, actor and temperature alike
    discount: float = 0.99
    tau: float = 0.005  # Polyak rate of the target critics
    target_entropy: Optional[float] = None  # None -> -|A| (Acme)
    init_temperature: float = 1.0
    hidden_sizes: Tuple[int, ...] = (256, 256)
    min_replay_size: int = 10_000
    max_replay_size: int = 1_000_000
    # The learner runs `updates_per_call` gradient steps (one lax.scan) every
    # `env_steps_per_call` agent steps (transitions): update-to-data ratio = their quotient.
    updates_per_call: int = 8
    env_steps_per_call: int = 8
    # The agent acts every `action_repeat` control steps (0.008 s each); the tendon
    # servos settle in ~1.5 s, so a decision per control step mostly adds noise.
    action_repeat: int = 1
    reward_scale: float = 1.0
    log_std_min: float = -5.0
    log_std_max: float = 2.0
    # Agent improvements beyond the paper's SAC; the defaults (off) are plain SAC.
    critic_layer_norm: bool = False  # LayerNorm in every hidden layer of both critics
    # Hindsight relabelling (HER, "future" strategy) on tasks whose reward is a function of the
    # achieved head pose and the goal (robostrich's Reach): this fraction of every sampled batch
    # gets a goal the head reached later in the same episode, with the reward recomputed exactly.
    her_ratio: float = 0.0
    # Recompute every sampled transition's reward with the current lesson's reward function
    # (needs the same goal-aware tasks): after a lesson switch, lesson-1 transitions in the
    # replay then carry lesson-2 rewards instead of the ones they were collected with.
    relabel_rewards: bool = False

    def __post_init__(self):
        if min(self.batch_size, self.updates_per_call, self.env_steps_per_call, self.action_repeat) <= 0:
            raise ValueError("batch_size, updates_per_call, env_steps_per_call and action_repeat must be positive")
        if not 0.0 < self.tau <= 1.0:
            raise ValueError(f"tau must be in (0, 1], got {self.tau}")
        if not 0.0 <= self.her_ratio <= 1.0:
            raise ValueError(f"her_ratio must be in [0, 1], got {self.her_ratio}")
        if self.min_replay_size > self.max_replay_size:
            raise ValueError("min_replay_size exceeds max_replay_size")
        object.__setattr__(self, "hidden_sizes", tuple(int(h) for h in self.hidden_sizes))

    @property
    def update_to_data_ratio(self) -> float:
        return self.updates_per_call / self.env_steps_per_call

    def resolved_target_entropy(self, action_size: int) -> float:
        return -float(action_size) if self.target_entropy is None else float(self.target_entropy)

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["hidden_sizes"] = list(self.hidden_sizes)
        return d

    @property
    def uses_goals(self) -> bool:
        """Whether the replay must keep achieved goals (for HER or reward recomputation)."""
        return self.her_ratio > 0.0 or self.relabel_rewards

    @classmethod
    def from_dict(cls, d: dict) -> "SACConfig":
        fields = {f.name for f in dataclasses.fields(cls)}
        unknown = set(d) - fields
        if unknown:
            raise ValueError(f"unknown SACConfig fields: {sorted(unknown)}")
        d = dict(d)
        if "hidden_sizes" in d:
            d["hidden_sizes"] = tuple(d["hidden_sizes"])
        return cls(**d)
