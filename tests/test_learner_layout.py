"""A run checkpointed by the earlier learner layout (two critic networks, Adam one array at a time)
resumes in this one's (the twin critics stacked, Adam on one vector per parameter group) with the
same critics and the same moments. The files in tests/data were written by the earlier code:
a 120-step lesson-1 run (seed 5, 8x8 networks) with each kind of critic, and its critics' values
on eight stored transitions."""
import pathlib

import jax
import jax.numpy as jnp
from jax.flatten_util import ravel_pytree
import numpy as np
import pytest

from agents import checkpoint
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, parse_plan
from agents.sac.config import SACConfig

DATA = pathlib.Path(__file__).parent / "data"


@pytest.mark.parametrize("kind, layer_norm, first_layer", [("mlp", False, "{}/~/linear_0"),
                                                          ("layer_norm", True, "{}_linear_0")])
def test_a_run_of_the_earlier_layout_resumes_with_the_same_critics_and_moments(tmp_path, kind, layer_norm, first_layer):
    config = SACConfig(batch_size=16, hidden_sizes=(8, 8), min_replay_size=50, max_replay_size=200,
                       critic_layer_norm=layer_norm)
    run = DomainRun(RunSpec(parse_plan("robostrich/lesson1:120"), config, 5),
                    str(tmp_path / "run"), checkpoint_every=10_000)
    path = str(DATA / f"learner_layout_v1_{kind}.ckpt")
    run.restore(path)
    learner = run.loop.learner
    assert learner.num_updates == 71 and len(run.loop.replay) == 120

    stored = np.load(DATA / f"learner_layout_v1_{kind}_q.npz")
    q1, q2 = learner.networks.q_apply(learner.state.q_params, jnp.asarray(stored["obs"]), jnp.asarray(stored["action"]))
    np.testing.assert_allclose(np.asarray(q1), stored["q1"], rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(np.asarray(q2), stored["q2"], rtol=1e-6, atol=1e-7)

    payload = checkpoint.load(path)["learner"]
    for twin, index in (("q1", 0), ("q2", 1)):
        earlier = payload[f".q_opt_state[0].nu['{first_layer.format(twin)}']['w']"]
        moments = ravel_pytree(learner.state.q_params)[1](learner.state.q_opt_state[0].nu)  # optax.flatten's order
        now = moments[first_layer.format("critic")]["w"]
        np.testing.assert_array_equal(np.asarray(now)[index], earlier)
    earlier = payload[".policy_opt_state[0].mu['mean']['w']"]
    now = ravel_pytree(learner.state.policy_params)[1](learner.state.policy_opt_state[0].mu)["mean"]["w"]
    np.testing.assert_array_equal(np.asarray(now), earlier)

    before = learner.num_updates  # and it learns on from there
    learner.step(run.loop.replay.sample_stack(2, config.batch_size, None))
    assert learner.num_updates == before + 2
    assert all(np.all(np.isfinite(leaf)) for leaf in jax.tree_util.tree_leaves(learner.get_state()))
