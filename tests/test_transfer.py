"""robostrich-train --init-from: an a1 run starts from a checkpoint of the arm on its frame (agents/robostrich/train/transfer.py).

Real JAX and MuJoCo at tiny sizes: a 300-step robostrich run gives the checkpoint.
"""
import dataclasses
import json

import jax
from jax.flatten_util import ravel_pytree
import numpy as np
import pytest
import robostrich_suite
from robostrich_suite.model import quadruped as quad
from robostrich_suite.tasks import quadruped_tasks

from agents import checkpoint
from agents.robostrich.train import transfer
from agents.robostrich.train.main_job import MAIN_JOB_SAC
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, parse_plan
from agents.sac.config import SACConfig
from test_cli import assert_succeeded, assert_user_error, call, finish, start

# The main job's agent (robostrich-train's defaults, so that its runs and these match), small.
TINY = dataclasses.replace(MAIN_JOB_SAC, hidden_sizes=(16, 16), batch_size=16, min_replay_size=50,
                           max_replay_size=2000, updates_per_call=2, env_steps_per_call=2)
TINY_ARGS = ["--hidden-sizes", "16,16", "--batch-size", "16", "--min-replay-size", "50", "--max-replay-size", "2000",
             "--updates-per-call", "2", "--env-steps-per-call", "2", "--num-eval-targets", "1",
             "--final-eval-targets", "1", "--quiet", "--no-rerun", "--no-figures"]
A1_PLAN = parse_plan("robostrich_a1/lesson2:100")


@pytest.fixture(scope="module")
def source(tmp_path_factory):
    """A trained robostrich run (temperature and Adam moments moved off their start) and its checkpoint."""
    run = DomainRun(RunSpec(parse_plan("robostrich/lesson2:300"), TINY, 0),
                    str(tmp_path_factory.mktemp("source")), checkpoint_every=10 ** 6)
    run.run()
    assert run.loop.learner.num_updates > 0
    return run, run.checkpoint_path


@pytest.fixture(scope="module")
def transferred(source, tmp_path_factory):
    run = DomainRun(RunSpec(A1_PLAN, TINY, 1), str(tmp_path_factory.mktemp("a1")))
    transfer.initialize(run, source[1])
    return run


def corresponding_states(count=4, seed=0):
    """(frame observation, a1 observation) pairs of one state: the a1 stands level at its nominal height after
    random tendon actions, the frame arm gets its joint angles, velocities and tendon inputs, and the target
    moves by frame_to_trunk's offset."""
    a1 = robostrich_suite.load("robostrich_a1", "lesson2", task_kwargs=dict(random=seed))
    frame = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=seed))
    a1.reset()
    frame.reset()
    rng, spec = np.random.default_rng(seed), a1.action_spec()
    a1_arm, frame_arm = a1.physics.arm_indices, frame.physics.arm_indices
    pairs = []
    for _ in range(count):
        for _ in range(15):
            a1.step(rng.uniform(spec.minimum, spec.maximum))
        data = a1.physics.data
        data.qpos[:7] = [0, 0, quad.STANDING_TRUNK_HEIGHT, 1, 0, 0, 0]  # level, at the nominal height
        data.qvel[:6] = 0
        a1.physics.forward()
        frame.physics.data.qpos[frame_arm.qpos] = data.qpos[a1_arm.qpos]
        frame.physics.data.qvel[frame_arm.dofs] = data.qvel[a1_arm.dofs]
        frame.physics.data.ctrl[frame_arm.actuators] = data.ctrl[a1_arm.actuators]
        frame.task.target_position = a1.task.target_position - quadruped_tasks.FRAME_TO_TRUNK_OFFSET
        frame.physics.forward()
        pairs.append((frame.task.get_observation(frame.physics), a1.task.get_observation(a1.physics)))
    return pairs


def test_transferred_networks_act_and_judge_as_the_source_on_corresponding_states(source, transferred):
    src, dst = source[0].loop, transferred.loop
    pairs = corresponding_states()
    frame_obs = np.stack([src.flattener(f) for f, _ in pairs])
    a1_obs = np.stack([dst.flattener(a) for _, a in pairs])
    s, t = src.learner.state, dst.learner.state
    networks_s, networks_t = src.learner.networks, dst.learner.networks
    np.testing.assert_allclose(networks_t.mode(t.policy_params, a1_obs), networks_s.mode(s.policy_params, frame_obs),
                               atol=1e-5)
    mean_s, log_std_s = networks_s.policy_apply(s.policy_params, frame_obs)
    mean_t, log_std_t = networks_t.policy_apply(t.policy_params, a1_obs)
    np.testing.assert_allclose(log_std_t, log_std_s, atol=1e-5)
    actions = np.random.default_rng(0).uniform(-1, 1, (len(pairs), 9)).astype(np.float32)
    for params in ("q_params", "target_q_params"):
        np.testing.assert_allclose(networks_t.q_apply(getattr(t, params), a1_obs, actions),
                                   networks_s.q_apply(getattr(s, params), frame_obs, actions), rtol=1e-5, atol=1e-5)
    # The actor acts with the transferred policy; temperature and Adam's step count carry over; the run
    # keeps its own RNG key and update counter, and records where it started.
    np.testing.assert_array_equal(jax.tree_util.tree_leaves(dst.actor.params)[0],
                                  jax.tree_util.tree_leaves(t.policy_params)[0])
    assert float(t.log_alpha) == float(s.log_alpha) != 0.0
    assert int(t.policy_opt_state[0].count) == int(s.policy_opt_state[0].count) > 0
    assert int(t.steps) == 0 and transferred.fingerprint()["init_from"] == transferred.spec.init_from
    assert transferred.spec.init_from == open(source[1], "rb").read(40)[8:].hex()


def new_input_rows(run):
    """Flat indices of the a1's inputs the frame has not: the 'left' components and the trunk's motion."""
    rows, start = [], 0
    for key, size in run.loop.flattener.describe():
        if key in ("trunk_position", "trunk_velocity"):
            rows += range(start, start + size)
        elif key in ("head_position", "head_velocity"):
            rows.append(start + 1)
        start += size
    return rows


def test_new_inputs_get_zero_rows_in_every_first_layer_and_its_moments(source, transferred):
    rows = new_input_rows(transferred)
    assert len(rows) == 8
    state = transferred.loop.learner.state
    source_state = source[0].loop.learner.state
    moments = {group: ravel_pytree(params)[1](getattr(state, f"{group}_opt_state")[0].mu)
               for group, params in (("policy", state.policy_params), ("q", state.q_params))}
    trees = {"policy": state.policy_params, "q": state.q_params, "target_q": state.target_q_params,
             "policy mu": moments["policy"], "q mu": moments["q"],
             "policy nu": ravel_pytree(state.policy_params)[1](state.policy_opt_state[0].nu),
             "q nu": ravel_pytree(state.q_params)[1](state.q_opt_state[0].nu)}
    for name, tree in trees.items():
        first = [m for m in tree if m.endswith("linear_0")]
        assert len(first) == 1, (name, list(tree))
        twins = 1 if name.startswith("policy") else 2  # the twin critics stacked
        w = np.asarray(tree[first[0]]["w"]).reshape(twins, *np.shape(tree[first[0]]["w"])[-2:])
        assert w.shape[1] == transferred.loop.flattener.size + (0 if name.startswith("policy") else 9)
        assert not np.any(w[:, rows]), name
        mapped = np.delete(w, rows, axis=1)
        assert np.count_nonzero(mapped) > 0.9 * mapped.size, name
    # A moment's row is the source's row (head_position's forward component is the frame's x), in
    # each of the twin critics.
    source_mu = ravel_pytree(source_state.q_params)[1](source_state.q_opt_state[0].mu)["critic_linear_0"]["w"]
    np.testing.assert_array_equal(np.asarray(moments["q"]["critic_linear_0"]["w"])[:, 0], np.asarray(source_mu)[:, 0])


def test_observation_map_follows_the_real_layouts():
    frame = robostrich_suite.load("robostrich", "lesson2").observation_spec()
    a1 = robostrich_suite.load("robostrich_a1", "lesson2").observation_spec()
    layout = lambda spec: [[k, int(np.prod(v.shape))] for k, v in spec.items()]  # noqa: E731
    obs_map = transfer.ObservationMap.between(layout(frame), layout(a1),
                                              *transfer.correspondence("robostrich", "robostrich_a1"))
    assert (obs_map.source_size, obs_map.target_size) == (46, 54) and len(obs_map.new_inputs) == 8
    x = np.arange(46.0)
    y = obs_map(x)
    np.testing.assert_allclose(y[:3], [x[0] + quadruped_tasks.FRAME_TO_TRUNK_OFFSET[0], 0.0,
                                       x[1] + quadruped_tasks.FRAME_TO_TRUNK_OFFSET[1]])
    same = transfer.ObservationMap.between(layout(frame), layout(frame))
    np.testing.assert_array_equal(same.index, np.arange(46))
    with pytest.raises(transfer.TransferError, match="no one counterpart"):  # a frame input left unread
        transfer.ObservationMap.between(layout(frame), [k for k in layout(frame) if k[0] != "to_target"])


def test_checkpoints_that_cannot_start_the_run_are_refused(source, tmp_path):
    run, path = source
    with pytest.raises(transfer.TransferError, match="cannot start a run on 'point_mass'"):
        transfer.check_source(path, parse_plan("point_mass/easy:10"), TINY)
    with pytest.raises(transfer.TransferError, match="hidden_sizes is \\(16, 16\\), this run's \\(32, 32\\)"):
        transfer.check_source(path, A1_PLAN, dataclasses.replace(TINY, hidden_sizes=(32, 32)))
    with pytest.raises(transfer.TransferError, match="critic_layer_norm"):
        transfer.check_source(path, A1_PLAN, dataclasses.replace(TINY, critic_layer_norm=False))
    with pytest.raises(transfer.TransferError, match=r"tendon layout 'ventral_slips', this run uses 'antagonist_pairs' \(pass --layout ventral_slips\)"):
        transfer.check_source(path, A1_PLAN, TINY, layout="antagonist_pairs")
    with pytest.raises(FileNotFoundError, match="no checkpoint file"):
        transfer.check_source(str(tmp_path / "missing.ckpt"), A1_PLAN, TINY)
    (tmp_path / "junk.ckpt").write_bytes(b"not a checkpoint")
    with pytest.raises(checkpoint.CheckpointError):
        transfer.check_source(str(tmp_path / "junk.ckpt"), A1_PLAN, TINY)
    fresh = DomainRun(RunSpec(A1_PLAN, TINY, 1), str(tmp_path / "a1"))
    with pytest.raises(transfer.TransferError, match="has changed"):
        transfer.initialize(fresh, path, digest="0" * 64)
    # The same domain with the same layout: a plain copy of the learner.
    same = DomainRun(RunSpec(parse_plan("robostrich/lesson3:100"), TINY, 5), str(tmp_path / "same"))
    transfer.initialize(same, path)
    for a, b in zip(jax.tree_util.tree_leaves(same.loop.learner.state[:7]),
                    jax.tree_util.tree_leaves(run.loop.learner.state[:7])):
        np.testing.assert_array_equal(a, b)


@pytest.mark.long
def test_train_from_a_frame_checkpoint_end_to_end(source, tmp_path):
    _, path = source
    out = tmp_path / "a1"
    bad = start("robostrich-train", "--domain", "robostrich_a1", "--init-from", tmp_path / "nope.ckpt",
                "--out", tmp_path / "bad", *TINY_ARGS)
    result = call("robostrich-train", "--domain", "robostrich_a1", "--init-from", path, "--steps", "600",
                  "--workers", "1", "--out", out, *TINY_ARGS)  # the source's layout, the default
    assert_succeeded(result)
    assert_user_error(finish(bad), "--init-from: no checkpoint file", "nope.ckpt")
    assert not (tmp_path / "bad").exists()
    digest = open(path, "rb").read(40)[8:].hex()
    curriculum = checkpoint.read_fingerprint(str(out / "curriculum" / "checkpoint.ckpt"))
    assert curriculum["init_from"] == digest and curriculum["plan"].count("robostrich_a1/") == 4
    assert "init_from" not in checkpoint.read_fingerprint(str(out / "baseline" / "checkpoint.ckpt"))
    assert json.loads((out / "config.json").read_text())["init_from"]["sha256"] == digest
    # A resume must come from the same checkpoint; another one is refused before anything is touched.
    other = call("robostrich-train", "--domain", "robostrich_a1", "--init-from", out / "baseline" / "checkpoint.ckpt",
                 "--steps", "600", "--out", out, "--resume", *TINY_ARGS)
    assert_user_error(other, "did not start from --init-from")


def test_a_target_that_keeps_a_policy_average_starts_it_at_the_source_s(source, tmp_path):
    import dataclasses
    source_state = jax.tree_util.tree_map(np.asarray, source[0].loop.learner.state)
    assert source_state.average_policy_params is not None  # TINY keeps the default average
    run = DomainRun(RunSpec(A1_PLAN, dataclasses.replace(TINY, policy_average=0.01), 1), str(tmp_path))
    obs_map = transfer.ObservationMap.between(source[0].loop.flattener.describe(), run.loop.flattener.describe(),
                                              *transfer.correspondence("robostrich", "robostrich_a1"))
    fresh = run.loop.learner.get_state()
    for source_average in (source_state.average_policy_params, None):  # None: paper SAC, older runs
        state = transfer.transfer_state(source_state._replace(average_policy_params=source_average), fresh, obs_map)
        expected = state.policy_params if source_average is None else transfer.map_params(source_average, obs_map)
        for a, b in zip(jax.tree_util.tree_leaves(state.average_policy_params),
                        jax.tree_util.tree_leaves(expected), strict=True):
            np.testing.assert_array_equal(a, b)
    assert not all(np.array_equal(a, b) for a, b in zip(jax.tree_util.tree_leaves(source_state.average_policy_params),
                                                      jax.tree_util.tree_leaves(source_state.policy_params)))
    plain = transfer.transfer_state(source_state, fresh._replace(average_policy_params=None), obs_map)
    assert plain.average_policy_params is None  # a target without an average keeps none
