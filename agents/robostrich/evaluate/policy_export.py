"""A trained run's deployable policy as a package policy file (robostrich_suite.policies).

Only what acting needs leaves the checkpoint: the evaluation parameters of the actor
(its moving average), the observation layout, the action bounds and the model
fingerprint, with the command, seed and run fingerprint that made it.
"""
import numpy as np

from agents import checkpoint
from agents.actors import ResidualAdapter
from agents.robostrich.evaluate.evaluation import default_heldout_task, load_run_from_checkpoint
from robostrich_suite import policies
from robostrich_suite import fingerprint as fingerprint_lib


def _layers(params: dict):
    """(hidden layers, mean head) of the policy network's haiku parameters."""
    torso = sorted((name for name in params if name.startswith("policy_torso")),
                   key=lambda name: int(name.rsplit("_", 1)[-1]))
    hidden = tuple((np.asarray(params[n]["w"], np.float32), np.asarray(params[n]["b"], np.float32)) for n in torso)
    mean = (np.asarray(params["mean"]["w"], np.float32), np.asarray(params["mean"]["b"], np.float32))
    return hidden, mean


def export_policy(checkpoint_path: str, out_path: str, command: str = "") -> policies.Policy:
    """Write the policy of the run that wrote ``checkpoint_path`` to ``out_path`` and return it."""
    run = load_run_from_checkpoint(checkpoint_path)
    if isinstance(run.loop.actor.adapter, ResidualAdapter):
        raise ValueError(f"{checkpoint_path}: a residual policy needs its base controller; only plain policies export")
    if run.config.action_repeat != 1:
        raise ValueError(f"{checkpoint_path}: the policy acts every {run.config.action_repeat} control steps; "
                         "a policy file acts every step")
    domain = run.domain()
    env = domain.make_environment(default_heldout_task(domain, run.plan[-1].task), 0)
    spec = env.action_spec()
    hidden, mean = _layers(run.loop.learner.evaluation_params)
    stored = checkpoint.read_fingerprint(checkpoint_path)
    policy = policies.Policy(
        hidden=hidden, mean=mean,
        observation_layout=tuple((str(k), int(s)) for k, s in run.loop.flattener.describe()),
        action_low=np.broadcast_to(np.asarray(spec.minimum, np.float64), spec.shape).copy(),
        action_high=np.broadcast_to(np.asarray(spec.maximum, np.float64), spec.shape).copy(),
        fingerprint=fingerprint_lib.compiled_fingerprint(env.physics.model),
        fine_input_gain=run.config.fine_input_gain, fine_inputs=tuple(run.config.fine_input_gains().items()),
        info={"layout": domain.layout, **domain.info(), "plan": stored.get("plan"), "seed": run.seed,
              "env_steps": run.loop.env_steps, "command": command, "run_fingerprint": stored})
    env.close()
    policy.save(out_path)
    return policy
