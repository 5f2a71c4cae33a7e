"""What a recording shows when it is opened: the whole robot (every link's shape), the target and
the head, in the layout it carries (robostrich_suite/rerun_blueprint.py), so that the native viewer
and `--web` open on the robot and its errors instead of Rerun's guess."""
import numpy as np
import rerun as rr

import robostrich_suite
from agents.robostrich.recording import RolloutRecorder, log_training_curves
from conftest import rrd_entities, rrd_view_names
from robostrich_suite import rerun_blueprint
from robostrich_suite.tasks.measurement import measure

ROLLOUT_VIEWS = [rerun_blueprint.ARM_VIEW] + [title for title, _ in rerun_blueprint.ROLLOUT_SERIES]


def _record(env, path, steps=3):
    with RolloutRecorder(str(path), name="layout") as recorder:
        timestep = env.reset()
        for _ in range(steps):
            action = np.zeros(env.action_spec().shape)
            timestep = env.step(action)
            recorder.log_step(env, action, timestep, measure(env))


def test_a_rollout_of_the_arm_shows_every_link_and_opens_in_the_rollout_layout(tmp_path):
    env = robostrich_suite.load("robostrich", "track")
    _record(env, tmp_path / "arm.rrd")
    entities = rrd_entities(tmp_path / "arm.rrd")
    links = [env.physics.model.id2name(i, "body").split("/")[-1] for i in range(env.physics.model.nbody)]
    links = [name for name in links if name.startswith("c") or name == "atlas"]
    assert len(links) == 18, links
    missing = [f"/world/bodies/arm_{link}/arm_{link}_geom" for link in links
               if f"/world/bodies/arm_{link}/arm_{link}_geom" not in entities]
    assert not missing, missing  # capsules were once skipped: a numpy geom type is never `in` a tuple of enums
    assert {"/world/target", "/world/head", "/world/head_path", "/plots/position_error_m"} <= entities
    assert sorted(rrd_view_names(tmp_path / "arm.rrd")) == sorted(ROLLOUT_VIEWS)
    names = [chunk.to_record_batch().column("SeriesLines:names").to_pylist()
             for chunk in rr.chunk.RrdReader(str(tmp_path / "arm.rrd")).stream()
             if chunk.entity_path == "/plots/tendon_input" and chunk.is_static]
    assert names == [[[tendon.split("/")[-1] for tendon in env.physics.tendon_names()]]], names  # not [0]..[8]


def test_the_arm_on_the_quadruped_shows_its_legs_and_training_curves_open_in_their_grid(tmp_path):
    env = robostrich_suite.load("robostrich_a1", "head_stabilize")
    _record(env, tmp_path / "a1.rrd", steps=2)
    entities = rrd_entities(tmp_path / "a1.rrd")
    assert {"/world/bodies/FL_thigh/FL_thigh", "/world/bodies/arm_atlas/arm_atlas_geom", "/world/target"} <= entities
    assert sorted(rrd_view_names(tmp_path / "a1.rrd")) == sorted(ROLLOUT_VIEWS)
    record = {"env_steps": 10, "return": 1.0, "success": 0.0}
    log_training_curves(str(tmp_path / "training.rrd"), {"curriculum": [record]},
                        {"curriculum": [{"env_steps": 10, "summary": {"success_rate": 0.5}}]})
    views = rrd_view_names(tmp_path / "training.rrd")
    assert {"return", "success", "held-out success rate"} <= set(views), views
