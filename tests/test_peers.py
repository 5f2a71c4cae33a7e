"""The peer agents (SBX's SAC, TQC, CrossQ) train through the gymnasium adapter and are scored by the
project's own evaluation; tools/benchmark_peers.py writes its record and figure, and says in one
line which extra it needs when sbx is missing."""
import json
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np
import pytest

pytest.importorskip("sbx")

from agents.curriculum import Lesson  # noqa: E402
from agents.robostrich.peers import sbx_agents as peers
from agents.robostrich.peers import benchmark as bench  # noqa: E402
from agents.robostrich.train import main_job  # noqa: E402
from agents.robostrich.domains import Domain  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
TOOLS = ROOT / "tools"


def tiny_spec(agent: str, way: str, plan: tuple, out) -> peers.PeerSpec:
    domain = Domain("robostrich")
    return peers.PeerSpec(agent, way, 0, plan, main_job.resolve_task_kwargs({}, domain),
                          main_job.resolve_layout(None, domain), "lesson2", None,
                          eval_at=(plan[0].steps, sum(l.steps for l in plan)), num_eval_targets=1,
                          final_eval_targets=1, out=str(out))


@pytest.mark.parametrize("agent", sorted(peers.PEERS))
def test_each_peer_trains_through_the_adapter_and_is_scored_by_our_evaluation(agent, tmp_path):
    """A few gradient steps past the published learning_starts (100), then the held-out evaluation
    from the fixed start and from the three moving starts, on real simulations."""
    result = peers.train(tiny_spec(agent, "final", (Lesson("robostrich", "lesson3", 110),), tmp_path))
    assert result["env_steps"] == 110
    assert [point["env_steps"] for point in result["curve"]] == [110]
    assert (tmp_path / "evals.jsonl").read_text().count("\n") == 1
    fixed, moving = result["final"]["heldout"], result["final"]["heldout_moving"]
    assert fixed["episodes"] == 1 and moving["episodes"] == 3
    assert 0.0 <= fixed["success_rate"] <= 1.0 and np.isfinite(fixed["position_error_median"])
    written = json.loads((tmp_path / "evaluation" / f"{agent}_final_heldout.json").read_text())
    assert len(written["episodes"]) == 1 and written["label"] == f"{agent}_final"


def test_a_peer_goes_through_the_lessons_with_its_replay(tmp_path, monkeypatch):
    """'lessons': one agent, the next lesson's environment at each boundary, evaluated at each; and
    nothing left in the temporary folder (stable-baselines3 makes a log folder per learn() unless told)."""
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    plan = (Lesson("robostrich", "lesson1", 60), Lesson("robostrich", "lesson2", 60), Lesson("robostrich", "lesson3", 60))
    spec = tiny_spec("sac", "lessons", plan, tmp_path)
    assert peers.segments(plan, spec.eval_at) == [(0, 60), (1, 60), (2, 60)]
    result = peers.train(spec)
    assert [point["env_steps"] for point in result["curve"]] == [60, 120, 180]
    assert list(scratch.iterdir()) == []


def test_the_peer_actor_gives_contractions_in_the_task_range(tmp_path):
    domain = Domain("robostrich")
    env = peers.make_env(domain, "lesson3", 0, main_job.resolve_task_kwargs({}, domain))
    model = peers.build_model("sac", env, 0)
    spec = env.dm_env.action_spec()
    observation, _ = env.reset(seed=0)
    action = peers.PeerActor(model, env).select_action(observation)
    assert action.shape == spec.shape and np.all(action >= spec.minimum) and np.all(action <= spec.maximum)


@pytest.mark.long
def test_the_command_writes_its_record_figure_and_table(tmp_path):
    """Our plain SAC, one peer and the lookup at a tiny budget, in worker processes as the real run."""
    sys.path.insert(0, str(TOOLS))
    import benchmark_peers
    import results_page
    out = tmp_path / "peers"
    assert benchmark_peers.cli(["--steps", "120", "--seeds", "0", "--agents", "plain,tqc", "--ways", "final",
                                "--eval-every", "60", "--num-eval-targets", "1", "--final-eval-targets", "1",
                                "--track-task", "", "--workers", "1", "--out", str(out)]) == 0
    data = json.loads((out / "peers.json").read_text())
    assert set(data["runs"]) == {"plain", "tqc_final"} and data["steps"] == 120
    assert [point[0] for point in data["runs"]["tqc_final"]["curves"][0]] == [60, 120]
    assert data["lookup"]["heldout"]["success_rate"] == 1.0  # the lookup holds the stored inputs
    assert (out / "learning_curves.png").stat().st_size > 10_000
    record = results_page.make_record("peers", str(out / "peers.json"), "Peers", date="2026-12-04")
    assert "SBX TQC, final lesson only" in results_page.render_record(record)
    assert bench.read_result(bench.Settings(120, (0,), ("tqc",), ("final",), str(out), 60, 1, 1, None),
                             "tqc_final", 0)["env_steps"] == 120
    # a stopped command's record: the finished runs, the others named; nothing finished is an error
    common = ["--steps", "120", "--seeds", "0", "--ways", "final", "--eval-every", "60", "--record-only"]
    assert benchmark_peers.cli(common + ["--agents", "plain,tqc,sac", "--out", str(out)]) == 0
    data = json.loads((out / "peers.json").read_text())
    assert set(data["runs"]) == {"plain", "tqc_final"} and data["unfinished"] == ["SBX SAC, final lesson only seed 0"]
    assert benchmark_peers.cli(common + ["--out", str(tmp_path / "empty")]) == 2


HIDE_SBX = """import sys
class _HideSbx:
    def find_spec(self, name, path=None, target=None):
        if name == "sbx" or name.startswith("sbx."):
            raise ModuleNotFoundError("No module named 'sbx'", name="sbx")
sys.meta_path.insert(0, _HideSbx())
"""


def test_without_the_extra_the_command_says_so_in_one_line(tmp_path):
    (tmp_path / "sitecustomize.py").write_text(HIDE_SBX)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, str(TOOLS / "benchmark_peers.py"), "--out", str(out)], env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "pip install -e '.[peers]'" in lines[0] and "sbx" in lines[0], done.stderr
    assert not out.exists()


def test_our_runs_take_the_flags_given_and_a_flag_robostrich_train_lacks_is_one_error():
    settings = bench.Settings(steps=300, seeds=(0,), agents=("curriculum",), ways=("final",), out="out",
                              eval_every=100, num_eval_targets=1, final_eval_targets=None, track_task=None,
                              ours_args=("--fine-input-gain", "0"))
    argv = bench.ours_argv(settings, "curriculum", 0)
    assert argv[-2:] == ["--fine-input-gain", "0"] and "--no-baseline" in argv
    bench.check_ours_args(("--fine-input-gain", "0"))
    with pytest.raises(ValueError, match="--ours-args: robostrich-train says unrecognized arguments: --bogus"):
        bench.check_ours_args(("--bogus",))
