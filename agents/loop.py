"""EnvironmentLoop: acts, stores transitions, and calls the learner every few steps.

Per agent step the Python work is: one numpy pass of the policy on the host, env.step (times
the action repeat), one flatten and one row insert. The learner is called
once per `config.env_steps_per_call` transitions with a whole stack of batches.
"""
import time
from typing import Callable, Optional

import numpy as np

from agents.actors import Actor
from agents.goals import GoalRelabeler
from agents.replay import ObservationFlattener, ReplayBuffer


class EnvironmentLoop:
    """Generic over the learner: anything with `step(batches) -> metrics` and `policy_params`; `config` gives
    the loop's schedule (action_repeat, min_replay_size, env_steps_per_call, updates_per_call, batch_size,
    her_ratio, relabel_rewards), e.g. an agents.sac.SACConfig. ``her_ratio`` starts at the config's; a
    curriculum sets it per lesson (curriculum.LessonSettings.her_lessons)."""

    def __init__(self, env, actor: Actor, replay: ReplayBuffer, learner, config,
                 flattener: ObservationFlattener, seed: int = 0, label: str = "",
                 episode_probe: Optional[Callable] = None):
        self.episode_probe = episode_probe  # env -> metrics of an episode's last state, for its record
        self.actor, self.replay, self.learner, self.config = actor, replay, learner, config
        self.flattener = flattener
        self.label = label
        self.env_steps = 0  # all environment (control) steps in this run, across lessons
        self.transitions = 0  # agent steps = transitions added to the replay
        self.episodes = 0
        self.warmup_rng = np.random.default_rng(seed + 7919)  # uniform actions before min_replay
        self.her_ratio = float(getattr(config, "her_ratio", 0.0))
        self.latest_metrics = {}
        self._set_env(env)

    def _set_env(self, env):
        self.env = env
        self.timestep = None  # reset lazily: a checkpointed env resumes mid-episode
        self.episode_return = 0.0
        self.episode_length = 0
        self._obs = None
        # The current lesson's goals and reward, when the replay keeps achieved goals.
        self.relabeler = GoalRelabeler.for_environment(env, self.flattener) if self.replay.goal_width else None

    def set_environment(self, env, close_episode: bool = True):
        """Switch lesson: the learner, actor and replay carry over (Algorithm 1).

        ``close_episode=False`` when a checkpointed environment resumes its open episode.
        """
        if close_episode:
            self.replay.end_episode()
        self._set_env(env)

    def episode_state(self):
        """(environment, last timestep, its flattened observation): what a checkpoint needs to resume
        the open episode exactly."""
        return self.env, self.timestep, self._obs

    def resume_episode(self, env, timestep, flat_obs):
        """Continue the open episode of a checkpointed environment (see `episode_state`)."""
        self.set_environment(env, close_episode=False)
        self.timestep, self._obs = timestep, flat_obs

    def _act(self, flat_obs):
        if len(self.replay) < self.config.min_replay_size:
            policy_action = self.warmup_rng.uniform(-1.0, 1.0, self.actor.adapter.size).astype(np.float32)
        else:
            policy_action = self.actor.policy_action(flat_obs)
        return policy_action

    def run(self, num_steps: int, on_episode: Optional[Callable] = None) -> int:
        """Run at least num_steps environment (control) steps; returns how many were run.

        With `config.action_repeat` k > 1 the agent acts every k control steps
        (one transition, rewards summed, discounts multiplied), so a call may
        overshoot by up to k - 1 steps; episodes may straddle calls.
        """
        env, replay, adapter, flatten = self.env, self.replay, self.actor.adapter, self.flattener
        cfg = self.config
        repeat = cfg.action_repeat
        relabeler = self.relabeler
        start = self.env_steps
        target = start + num_steps
        while self.env_steps < target:
            if self.timestep is None or self.timestep.last():
                self.timestep = env.reset()
                self._obs = flatten(self.timestep.observation)
                self.episode_return, self.episode_length = 0.0, 0
            obs = self._obs
            policy_action = self._act(obs)
            env_action = adapter.to_env(policy_action, obs)
            timestep = env.step(env_action)
            reward, discount, taken = float(timestep.reward), float(timestep.discount), 1
            next_obs = flatten(timestep.observation)
            substeps = [relabeler.substep(next_obs)] if relabeler is not None else None
            while taken < repeat and not timestep.last():
                timestep = env.step(env_action)
                reward += float(timestep.reward)  # as Acme's ActionRepeat: summed, undiscounted
                discount *= float(timestep.discount)
                taken += 1
                next_obs = flatten(timestep.observation)
                if substeps is not None:
                    substeps.append(relabeler.substep(next_obs))
            goal_free = (relabeler.goal_free(reward, substeps, obs)
                         if relabeler is not None and relabeler.keeps_goal_free else None)
            replay.add(obs, policy_action, reward, discount, next_obs, substeps, goal_free)
            self.timestep, self._obs = timestep, next_obs
            self.episode_return += reward
            self.episode_length += taken
            self.env_steps += taken
            self.transitions += 1
            if self.transitions % cfg.env_steps_per_call == 0 and len(replay) >= cfg.min_replay_size:
                batches = replay.sample_stack(cfg.updates_per_call, cfg.batch_size, relabeler,
                                              self.her_ratio, cfg.relabel_rewards)
                self.latest_metrics = self.learner.step(batches)
                self.actor.update(self.learner.policy_params)
            if timestep.last():
                replay.end_episode()
                self.episodes += 1
                if on_episode is not None:
                    on_episode(self._episode_record())
        return self.env_steps - start

    def _episode_record(self) -> dict:
        probed = self.episode_probe(self.env) if self.episode_probe is not None else {}
        return {"env_steps": self.env_steps, "episode": self.episodes,
                "return": self.episode_return, "length": self.episode_length, **probed, "time": time.time()}

    def cut_episode(self) -> Optional[dict]:
        """Count the open episode that a lesson's end cuts off and return its metrics (``"cut":
        true``), or None if none is open: without it the steps of cut episodes would be missing
        from the metrics."""
        if self.timestep is None or self.timestep.last() or self.episode_length == 0:
            return None
        self.episodes += 1
        return {**self._episode_record(), "cut": True}

    def metrics_as_floats(self) -> dict:
        return {k: float(v) for k, v in self.latest_metrics.items()}

    def state_dict(self) -> dict:
        return {"env_steps": self.env_steps, "transitions": self.transitions, "episodes": self.episodes,
                "warmup_rng": self.warmup_rng.bit_generator.state,
                "episode_return": self.episode_return, "episode_length": self.episode_length}

    def load_state_dict(self, d: dict):
        self.env_steps, self.transitions, self.episodes = d["env_steps"], d["transitions"], d["episodes"]
        self.warmup_rng.bit_generator.state = d["warmup_rng"]
        self.episode_return, self.episode_length = d["episode_return"], d["episode_length"]
