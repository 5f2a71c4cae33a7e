"""The generated arm matches Table 1 and its tendons act the way a neck's muscles do."""
import dataclasses

import mujoco
import numpy as np
import pytest
from dm_control import mjcf

from robostrich_suite import physics as physics_lib
from robostrich_suite import export_xml
from robostrich_suite import scenes
from robostrich_suite.model import arm, table1
from robostrich_suite.robostrich import Physics, get_model_and_assets


@pytest.fixture(scope="module")
def physics():
    return Physics.from_xml_string(*get_model_and_assets())


def test_table1_totals():
    assert table1.TOTAL_MASS_G == 287
    assert table1.TOTAL_LENGTH_MM == pytest.approx(611.4)
    assert len(table1.rows()) == 18


def test_joints_match_table1_in_radians(physics):
    names = physics.arm_joint_names()
    assert names == [f"arm/{n}" for n in table1.JOINT_NAMES]
    ranges = physics.named.model.jnt_range[names]
    np.testing.assert_allclose(ranges[:, 0], -np.radians(table1.DORSAL_LIMIT_DEG), atol=1e-12)
    np.testing.assert_allclose(ranges[:, 1], np.radians(table1.VENTRAL_LIMIT_DEG), atol=1e-12)
    assert np.all(physics.model.jnt_limited[[physics.model.name2id(n, "joint") for n in names]])


def test_link_lengths_are_distances_between_joint_axes(physics):
    physics.reset()
    anchors = np.array(physics.named.data.xanchor[physics.arm_joint_names()])  # atlas first
    distances = np.linalg.norm(np.diff(anchors, axis=0), axis=1)  # atlas-C2, C2-C3, ...
    expected = np.array(table1.LENGTH_MM[1:]) / 1000.0  # link C2 spans atlas..C2 joints
    np.testing.assert_allclose(distances, expected, atol=1e-9)


def test_masses_match_table1(physics):
    bodies = [f"arm/{n}" for n in table1.JOINT_NAMES]
    np.testing.assert_allclose(physics.named.model.body_mass[bodies],
                               np.array(table1.MASS_G) / 1000.0, atol=1e-12)
    assert physics.named.model.body_mass[bodies].sum() == pytest.approx(0.287, abs=1e-12)


def test_default_layout_is_one_dorsal_and_eight_ventral():
    """The tasks' arm is the reconstruction of Fig. 1B: one dorsal tendon to the head, eight
    ventral slips at the paper's insertion levels; the model the suite loads has just these."""
    layout = arm.TendonLayout.robostrich()
    assert layout == arm.TendonLayout.ventral_slips(span=4)
    assert [t.side for t in layout.tendons] == ["dorsal"] + ["ventral"] * 8
    assert layout.tendons[0].insertion == "atlas" and layout.tendons[0].on_base
    assert [t.insertion for t in layout.tendons[1:]] == list(
        arm.TendonLayout.ROBOSTRICH_VENTRAL_INSERTIONS)
    model = Physics.from_xml_string(*get_model_and_assets()).model
    assert physics_lib.tendon_sides(model) == ["dorsal"] + ["ventral"] * 8
    from_base = arm.TendonLayout.ventral_from_base()
    assert all(t.links[0] == "c18" and t.on_base for t in from_base.tendons)
    assert [t.insertion for t in from_base.tendons] == [t.insertion for t in layout.tendons]


def test_links_do_not_pass_through_each_other():
    """Links two or more joints apart collide (as vertebrae do), except where their capsules
    already touch with the neck straight; parent and child never do."""
    spec = arm.ArmSpec.from_table1()
    physics = Physics.from_xml_string(*get_model_and_assets())
    assert arm.touching_link_pairs(spec) == [("c3", "atlas")]  # link C2 (7.1 mm) is shorter than the radii
    physics.reset()
    physics.forward()
    assert physics.data.ncon == 0  # the straight neck touches nothing
    # Bend C9, C8 and C7 far ventral, past their limits, so that capsules two and more links
    # apart cross: the contacts report them overlapping by over half a centimetre.
    with physics.reset_context():
        physics.named.data.qpos[["arm/c9", "arm/c8", "arm/c7"]] = 1.3
    geoms = {physics.model.id2name(int(g), "geom") for c in physics.data.contact[:physics.data.ncon]
             for g in (c.geom1, c.geom2)}
    assert physics.data.ncon > 0 and geoms <= {f"arm/{n}_geom" for n in spec.joint_names}
    assert min(c.dist for c in physics.data.contact[:physics.data.ncon]) < -0.005


def test_every_tendon_only_pulls(physics):
    assert np.all(physics.model.actuator_forcerange[:, 1] == 0)
    assert np.all(physics.model.actuator_forcerange[:, 0] < 0)
    low, high = physics.model.actuator_ctrlrange.T
    rng = np.random.default_rng(0)
    for _ in range(5):
        physics.reset()
        physics.data.ctrl[:] = rng.uniform(low, high)
        for _ in range(100):
            physics.step()
            assert np.all(physics.tendon_forces() >= 0)


def _settle(physics, ctrl, steps=600):
    physics.reset()
    physics.data.ctrl[:] = ctrl
    physics.step(steps)
    return physics.head_position(), physics.head_attitude()


def test_ventral_tendons_flex_forward_and_dorsal_tendon_extends_back(physics):
    rest_head, rest_attitude = _settle(physics, np.zeros(9))
    np.testing.assert_allclose(rest_head[[0, 2]], [0, 0.05 + 0.03 + arm.reach(
        arm.ArmSpec.from_table1())], atol=2e-3)  # upright
    assert abs(rest_attitude) < 1.0
    ventral = np.zeros(9)
    ventral[0] = physics.model.actuator_ctrlrange[0, 0]  # let the dorsal tendon pay out
    ventral[1:] = 0.5 * physics.model.actuator_ctrlrange[1:, 1]
    head, attitude = _settle(physics, ventral)
    assert head[0] > rest_head[0] + 0.15  # head forward (ventral side is +x)
    assert head[2] < rest_head[2] - 0.1  # and lower
    assert attitude > 45  # head pitched forward/down
    dorsal = np.zeros(9)
    dorsal[0] = 0.03
    dorsal[1:] = physics.model.actuator_ctrlrange[1:, 0]
    head, attitude = _settle(physics, dorsal)
    assert head[0] < rest_head[0] - 0.1  # head backward
    assert attitude < -30


def test_checked_in_xml_is_up_to_date(repo_xml_dir):
    for name, generate in export_xml.generators().items():
        path = repo_xml_dir / name
        assert path.exists(), f"xml/{name} is missing: run robostrich-export-xml --out xml"
        assert path.read_text() == generate(), (
            f"xml/{name} is out of date: run robostrich-export-xml --out xml")


def test_checked_in_xml_loads_in_plain_mujoco(repo_xml_dir):
    model = mujoco.MjModel.from_xml_path(str(repo_xml_dir / "robostrich.xml"))
    assert (model.njnt, model.ntendon, model.nu) == (18, 9, 9)


def test_generator_takes_another_spec_and_layout():
    spec = arm.ArmSpec(joint_names=("head", "n2", "n3", "n4"), dorsal_limits_deg=(5, 20, 20, 20),
                       ventral_limits_deg=(5, 20, 20, 20), link_lengths=(0.05, 0.05, 0.05),
                       masses=(0.05, 0.01, 0.01, 0.01))
    layout = arm.TendonLayout((
        arm.TendonSpec("back", "dorsal", ("n4", "n3", "n2", "head")),
        arm.TendonSpec("front_low", "ventral", ("n4", "n3")),
        arm.TendonSpec("front_high", "ventral", ("n4", "n2"))))  # skips the n3 hole
    physics = mjcf.Physics.from_mjcf_model(scenes.build_frame_arm(spec, layout))
    assert (physics.model.njnt, physics.model.nu) == (4, 3)
    assert physics.model.tendon_num.tolist() == [5, 3, 3]  # anchor + holes


@pytest.mark.parametrize("change, message", [
    (dict(masses=(0.083,) + (-0.005,) + (0.01,) * 16), "link 'c2': mass"),
    (dict(dorsal_limits_deg=(1, -12) + (10,) * 16), "joint 'c2': dorsal limit"),
    (dict(ventral_limits_deg=(1, 12, -16) + (10,) * 15), "joint 'c3': ventral limit"),
    (dict(link_lengths=(0.0071, 0.0) + (0.04,) * 15), "link 'c3': length"),
    (dict(link_lengths=(0.01,) * 3), "link_lengths has 3 entries"),
    (dict(joint_names=("atlas",) + ("c2",) * 17), "duplicate joint/link names"),
    (dict(joint_stiffness=float("nan")), "joint_stiffness must be finite"),
    (dict(joint_damping=float("nan")), "joint_damping must be finite"),
    (dict(masses=(float("inf"),) + (0.01,) * 17), "masses must be finite"),
    (dict(tendon_kp=float("inf")), "tendon_kp must be finite"),
    (dict(anchor_depth=float("nan")), "anchor_depth must be finite"),
    (dict(joint_names=("",) + tuple(f"c{i}" for i in range(2, 19))), "joint/link name '' must be"),
])
def test_bad_spec_raises_naming_the_item(change, message):
    spec = dataclasses.replace(arm.ArmSpec.from_table1(), **change)
    with pytest.raises(ValueError, match=message):
        arm.build_arm(spec)


@pytest.mark.parametrize("tendons, message", [
    ((arm.TendonSpec("t", "ventral", ("c18", "c99")),), "unknown link 'c99'"),
    ((arm.TendonSpec("t", "ventral", ("c18",)),), "at least two"),
    ((arm.TendonSpec("t", "ventral", ("c18", "c17")),
      arm.TendonSpec("t", "dorsal", ("c18", "c17"))), "duplicate tendon name 't'"),
    ((arm.TendonSpec("t", "lateral", ("c18", "c17")),), "unknown side 'lateral'"),
    ((arm.TendonSpec("t", "ventral", ("c17", "c18")),), "caudal to cranial"),
    ((), "at least one tendon"),
    ((arm.TendonSpec("dorsal\tx", "dorsal", ("c18", "c17")),), "tendon name 'dorsal.*' must be a non-empty printable"),
])
def test_bad_layout_raises_naming_the_item(tendons, message):
    with pytest.raises(ValueError, match=message):
        arm.build_arm(layout=arm.TendonLayout(tendons))


def test_spanning_rejects_unknown_insertion():
    with pytest.raises(ValueError, match="unknown link 'neck'"):
        arm.TendonSpec.spanning("t", "ventral", "neck", arm.ArmSpec.from_table1())


def _tendon_joints(physics, tendon):
    """Names of the joints whose rotation changes a tendon's length (by finite differences
    from the straight pose: MuJoCo stores the tendon Jacobian sparsely)."""
    joints = [physics.model.id2name(j, "joint") for j in range(physics.model.njnt)]
    with physics.reset_context():
        base = float(physics.named.data.ten_length[tendon])
    moved = set()
    for joint in joints:
        with physics.reset_context():
            physics.named.data.qpos[joint] = 0.05
        if abs(physics.named.data.ten_length[tendon] - base) > 1e-6:
            moved.add(joint.split("/")[-1])
    return moved


def test_tendon_tied_between_vertebrae_acts_only_on_its_own_joints():
    spec = arm.ArmSpec.from_table1()
    slip = arm.TendonSpec.spanning("slip", "ventral", "c6", spec, origin="c10")
    assert not slip.on_base and slip.links == ("c10", "c9", "c8", "c7", "c6")
    layout = arm.TendonLayout((arm.TendonSpec.spanning("dorsal", "dorsal", "atlas", spec), slip))
    physics = mjcf.Physics.from_mjcf_model(scenes.build_frame_arm(spec, layout))
    assert physics.model.tendon_num.tolist() == [19, 5]  # base anchor + 18 holes; 5 holes
    assert _tendon_joints(physics, "arm/slip") == {"c9", "c8", "c7", "c6"}
    assert len(_tendon_joints(physics, "arm/dorsal")) == 18
    # Without gravity and with the dorsal tendon paid out (slack), contracting the slip
    # flexes exactly those joints ventrally.
    physics.model.opt.gravity[:] = 0
    physics.named.data.ctrl["arm/dorsal"] = physics.named.model.actuator_ctrlrange["arm/dorsal"][0]
    physics.named.data.ctrl["arm/slip"] = physics.named.model.actuator_ctrlrange["arm/slip"][1]
    for _ in range(3000):
        physics.step()
    angles = dict(zip(spec.joint_names, np.degrees(physics.named.data.qpos[
        [f"arm/{n}" for n in spec.joint_names]])))
    # Measured: 24-26 deg inside; outside, the floppy chain still rocks by ~1 deg from
    # the reaction of the bend (weak joints, no gravity to settle it).
    assert all(angles[n] > 15 for n in ("c9", "c8", "c7", "c6"))  # ventral flexion
    assert all(abs(angles[n]) < 2 for n in angles if n not in ("c9", "c8", "c7", "c6"))


def test_ventral_slips_layout():
    spec = arm.ArmSpec.from_table1()
    layout = arm.TendonLayout.ventral_slips(spec, span=4)
    assert layout.names == arm.TendonLayout.robostrich(spec).names
    slips = layout.tendons[1:]
    assert [t.links[0] for t in slips] == ["c18", "c18", "c16", "c14", "c12", "c10", "c8", "c6"]
    assert [t.on_base for t in slips] == [True, True] + [False] * 6  # c18 is the base link
    physics = mjcf.Physics.from_mjcf_model(scenes.build_frame_arm(spec, layout))
    assert _tendon_joints(physics, "arm/ventral_c8") == {"c11", "c10", "c9", "c8"}
    with pytest.raises(ValueError, match="span must be a positive"):
        arm.TendonLayout.ventral_slips(spec, span=0)


def test_tendon_sides_come_from_the_model_not_the_names():
    """The dorsal tendon is found by its side wherever the layout lists it and whatever it
    is called: here a ventral tendon named 'dorsal' comes first and the dorsal one third."""
    spec = arm.ArmSpec.from_table1()
    layout = arm.TendonLayout((
        arm.TendonSpec.spanning("dorsal", "ventral", "c4", spec),
        arm.TendonSpec.spanning("v2", "ventral", "c8", spec),
        arm.TendonSpec.spanning("pull_back", "dorsal", spec.head_name, spec),
    ))
    model = mjcf.Physics.from_mjcf_model(scenes.build_frame_arm(spec, layout)).model
    assert physics_lib.tendon_sides(model) == ["ventral", "ventral", "dorsal"]
    assert physics_lib.dorsal_index(model) == 2
    assert physics_lib.ventral_indices(model) == [0, 1]
    default = Physics.from_xml_string(*get_model_and_assets()).model
    assert physics_lib.dorsal_index(default) == 0 and physics_lib.ventral_indices(default) == list(range(1, 9))


def test_arm_indices_name_what_they_find():
    """arm_indices finds the arm by its prefix, in Table 1 and action order, on the frame and
    on the quadruped (whose legs it must skip)."""
    from robostrich_suite import robostrich_a1
    for physics in (Physics.from_xml_string(*get_model_and_assets()),
                    robostrich_a1.Physics.from_xml_string(*robostrich_a1.get_model_and_assets())):
        model = physics.model
        indices = physics_lib.arm_indices(model)
        assert [model.id2name(int(j), "joint") for j in indices.joints] == [
            f"arm/{n}" for n in arm.ArmSpec.from_table1().joint_names]
        assert [model.id2name(int(a), "actuator") for a in indices.actuators] == [
            f"arm/{n}" for n in arm.TendonLayout.robostrich().names]
        assert [model.id2name(int(t), "tendon") for t in indices.tendons] == [
            f"arm/{n}" for n in arm.TendonLayout.robostrich().names]
        assert model.id2name(indices.head_site, "site") == arm.HEAD_SITE_PATH
        assert model.site_bodyid[indices.head_site] == indices.head_body
        with physics.reset_context():
            pass  # straight neck: every tendon at its rest length
        np.testing.assert_allclose(indices.rest_lengths, physics.data.ten_length[indices.tendons],
                                   atol=1e-9)
