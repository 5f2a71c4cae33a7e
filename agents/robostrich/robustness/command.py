"""`robostrich-robustness`: how far a policy's success falls when the robot differs from its model.

A researcher building the arm asks this first. Each family of differences
(robostrich_suite/tasks/perturbations.py, which defines what scale s means for each) is applied
alone at increasing scales, then all at once, and the held-out evaluation (agents/robostrich/
evaluation.py: success from the fixed start and from moving starts, median errors) is run on the
perturbed robot; the lookup baseline beside the policy, a second policy optional. Every policy
meets the same robots: the draws come from the evaluation's seeds, not from the policy.
Writes robustness.json (a results record, tools/results_robustness.py) and robustness.png.
On the quadruped the held-out targets are also judged while it walks (its lesson 4, the trunk
height changing): standing, the gait's timing has nothing to act on.
"""
import argparse
import dataclasses
import os


from agents.replay import ObservationFlattener
from agents.robostrich.evaluate import episodes, evaluation
from agents.robostrich.robustness import figure as robustness_figure
from agents.robostrich.domains import as_domain, Domain, domain_of
from agents.robostrich.lookup import LABEL, LookupPolicy
from agents.sac.builder import SACBuilder
from robostrich_suite import atomic_files, outputs, policies
from robostrich_suite import cli as cli_lib
from robostrich_suite.tasks import perturbations

DEFAULT_SCALES = (0.0, 0.1, 0.2, 0.3, 0.5)
ALL = "all"  # every family of the domain at once
KINDS = tuple(robustness_figure.KINDS)
SUMMARY_FIELDS = ("episodes", "success_rate", "precise_success_rate", "position_error_median",
                  "attitude_error_median")
BENCHMARK = "robustness"  # the results record's kind (tools/results_page.py)


class PerturbedDomain(Domain):
    """A domain whose environments carry a ``perturbation`` task option (the evaluation builds
    its environments through ``Domain.make_environment``)."""

    def __init__(self, domain: Domain, perturbation: perturbations.Perturbation):
        super().__init__(domain.name, domain.layout, domain.sent_actions)
        object.__setattr__(self, "perturbation", perturbation)

    def make_environment(self, task: str, seed: int, **task_kwargs):
        return super().make_environment(task, seed, perturbation=self.perturbation, **task_kwargs)


def scale_list(text: str) -> tuple:
    """argparse type of --scales: comma-separated scales from 0 to 1, sorted, without repeats; an
    empty item (``0,,0.1``) is refused, not dropped."""
    parts = [part.strip() for part in text.split(",")]
    if not all(parts):
        raise argparse.ArgumentTypeError(f"must be numbers separated by single commas, got {text!r} (an empty item)")
    try:
        values = sorted({float(part) for part in parts})
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be numbers separated by commas, got {text!r}") from None
    if not values or any(not 0 <= v <= perturbations.MAX_SCALE for v in values):
        raise argparse.ArgumentTypeError(f"must be scales from 0 to {perturbations.MAX_SCALE:g}, got {text!r}")
    return tuple(values)


def families_of(domain) -> tuple:
    """The families that apply to ``domain``: the arm's, and on the quadruped its own two."""
    domain = as_domain(domain)
    return perturbations.FAMILIES if domain.on_quadruped else perturbations.ARM_FAMILIES


def conditions(domain, scales) -> list:
    """(family, scale, Perturbation): the nominal robot once, then each family and all at once at
    every scale above 0 (scale 0 of every family is the nominal robot)."""
    families = families_of(domain)
    rows = [("nominal", 0.0, perturbations.Perturbation())]
    for family in families + (ALL,):
        for scale in scales:
            if scale > 0:
                rows.append((family, scale, perturbations.Perturbation.of(
                    families if family == ALL else family, scale)))
    return rows


class Evaluated:
    """A policy to evaluate: label, actor (``select_action``), flattener, domain, action repeat."""

    def __init__(self, label, actor, flattener, domain, action_repeat=1, source=None):
        self.label, self.actor, self.flattener = label, actor, flattener
        self.domain, self.action_repeat, self.source = as_domain(domain), action_repeat, source


def load_evaluated(spec: str, label: str) -> Evaluated:
    """A shipped policy's name, a policy file (.npz) or a robostrich-train checkpoint (.ckpt)."""
    if spec.endswith(".ckpt"):
        if not os.path.isfile(spec):
            raise ValueError(f"no checkpoint {spec}")
        fingerprint = evaluation.checked_fingerprint(spec)
        domain = evaluation.checkpoint_domain(fingerprint)
        run = evaluation.load_run_from_checkpoint(spec)
        return Evaluated(label, SACBuilder.make_eval_actor(run.loop), run.loop.flattener, domain,
                         run.config.action_repeat, spec)
    policy = policies.load_policy(spec)
    domain = domain_of(policy.info)
    env = domain.make_environment(evaluation.default_heldout_task(domain, "track"), 0)
    policy.check(env)
    env.close()
    return Evaluated(label, policy, policy.flatten, domain, 1, spec)


def lookup_evaluated(domain) -> Evaluated:
    domain = as_domain(domain)
    env = domain.make_environment(evaluation.default_heldout_task(domain, "track"), 0)
    flattener = ObservationFlattener(env.observation_spec())
    env.close()
    return Evaluated(LABEL, LookupPolicy(flattener, domain.lookup_table()), flattener, domain, 1, LABEL)


def evaluate(evaluated: Evaluated, perturbation, num_targets) -> dict:
    """The held-out evaluation on the perturbed robot: {kind: its summary's main numbers}."""
    domain = PerturbedDomain(evaluated.domain, perturbation)
    task = evaluation.default_heldout_task(domain, "track")
    reports = {"heldout": episodes.evaluate_heldout(evaluated.actor, evaluated.flattener, domain, task,
                                                      domain.heldout_targets(num_targets), num_targets,
                                                      action_repeat=evaluated.action_repeat)}
    if domain.has_moving_starts:
        reports["heldout_moving"] = episodes.evaluate_heldout_moving(
            evaluated.actor, evaluated.flattener, domain, num_targets, action_repeat=evaluated.action_repeat)
    if domain.walking_task:
        reports["walking"] = episodes.evaluate_heldout(evaluated.actor, evaluated.flattener, domain, domain.walking_task,
                                                       domain.heldout_targets(num_targets), num_targets,
                                                       action_repeat=evaluated.action_repeat, kind="walking")
    return {kind: {k: report["summary"][k] for k in SUMMARY_FIELDS} for kind, report in reports.items()}


def measure(evaluated_list, domain, scales, num_targets, progress=True) -> dict:
    """{label: {family: [{"scale", kind: summary}...]}}, scale 0 (the nominal robot) in every family."""
    rows = conditions(domain, scales)
    from tqdm import tqdm
    bar = tqdm(total=len(rows) * len(evaluated_list), desc="robustness", unit="condition", disable=not progress)
    results = {}
    try:
        for evaluated in evaluated_list:
            nominal, by_family = None, {}
            for family, scale, perturbation in rows:
                bar.set_postfix_str(f"{evaluated.label} {family} {scale:g}")
                row = {"scale": scale, **evaluate(evaluated, perturbation, num_targets)}
                bar.update()
                if family == "nominal":
                    nominal = row
                    continue
                by_family.setdefault(family, [nominal] if 0.0 in scales else []).append(row)
            if not by_family:  # --scales 0: only the nominal robot
                by_family = {f: [nominal] for f in families_of(domain) + (ALL,)}
            results[evaluated.label] = by_family
    except BaseException:
        bar.leave = False
        raise
    finally:
        bar.close()
    return results


def thresholds(rows, kind="heldout", levels=(0.9, 0.8)) -> dict:
    """The smallest measured scale at which success falls below each level (None: never)."""
    return {f"{level:g}": next((r["scale"] for r in rows if r[kind]["success_rate"] < level), None)
            for level in levels}


def summary(args, evaluated_list, results, domain) -> dict:
    main = evaluated_list[0].label
    return {
        "benchmark": BENCHMARK, "command": args.command_line, "policy": args.policy, "compare": args.compare,
        "domain": as_domain(domain).describe(), "num_targets": args.num_targets or len(
            as_domain(domain).heldout_targets()), "scales": list(args.scales),
        "families": list(families_of(domain)) + [ALL], "labels": [e.label for e in evaluated_list],
        "definitions": "robostrich_suite/tasks/perturbations.py",
        "results": results,
        "falls_below": {family: thresholds(rows) for family, rows in results[main].items()},  # the policy, fixed start
        "falls_below_by_label": {label: {family: {kind: thresholds(rows, kind) for kind in KINDS if kind in rows[0]}
                                         for family, rows in families.items()}
                                 for label, families in results.items()},
    }


def summary_lines(report: dict) -> list:
    """Per policy (and the lookup) and family, where held-out success falls below 90 % and 80 %,
    in each evaluation (robustness_figure.KINDS): what the figure shows, in words."""
    lines = []
    for label, families in report["falls_below_by_label"].items():
        lines.append(f"{label}: held-out success, where it falls below 90 % / 80 % as the robot differs more")
        for family, kinds in families.items():
            parts = []
            for kind, levels in kinds.items():
                falls = ", ".join(f"below {float(k) * 100:.0f} % at s = {v}" for k, v in levels.items() if v is not None)
                parts.append(f"{robustness_figure.KINDS[kind]}: {falls or 'above 90 % at every scale measured'}")
            lines.append(f"  {family:14s} " + "; ".join(parts))
    return lines


def build_parser() -> cli_lib.Parser:
    parser = cli_lib.Parser(prog="robostrich-robustness",
                            description="Held-out success of a policy (and the lookup baseline) as the robot "
                                        "differs from its model: one family of differences at a time at "
                                        "increasing scale, then all at once. Writes robustness.json and .png.",
                            epilog="What scale s does to each family (per episode, relative to the model): "
                                   + cli_lib.doc_excerpt(perturbations.__doc__, "* ``mass``", "With ``vary``", {
                                       "TENDON_LENGTH_AT_1": f"{perturbations.TENDON_LENGTH_AT_1:g} m",
                                       "FRICTION_AT_1": f"{perturbations.FRICTION_AT_1:g} N m",
                                       "JOINT_NOISE_AT_1": f"{perturbations.JOINT_NOISE_AT_1:g} rad",
                                       "LATENCY_STEPS_PER_SCALE": f"{perturbations.LATENCY_STEPS_PER_SCALE:g}",
                                       "MAX_LATENCY_STEPS": f"{perturbations.MAX_LATENCY_STEPS}",
                                       "TRUNK_HEIGHT_AT_1": f"{perturbations.TRUNK_HEIGHT_AT_1:g} m"}))
    parser.add_argument("policy", help=f"a shipped policy ({', '.join(policies.SHIPPED)}), a policy file (.npz) "
                                       "or a robostrich-train checkpoint (checkpoint.ckpt)")
    parser.add_argument("--out", default="out/robustness", help="directory for robustness.json and .png (default: %(default)s)")
    parser.add_argument("--scales", type=scale_list, default=DEFAULT_SCALES,
                        help="scales s, comma-separated, 0 to 1 (default: " + ",".join(f"{s:g}" for s in DEFAULT_SCALES)
                             + "); what s means per family: below")
    parser.add_argument("--num-targets", type=evaluation.target_count, default=None,
                        help="held-out targets (default: all)")
    parser.add_argument("--lookup", action=argparse.BooleanOptionalAction, default=True,
                        help="evaluate the lookup baseline beside the policy (default: on)")
    parser.add_argument("--compare", default=None, help="a second policy (same forms as POLICY) in the figure")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    return parser


def _check_out(out: str) -> None:
    """--out must be a directory we may write (before any work)."""
    outputs.check_directory(out)
    os.makedirs(out, exist_ok=True)


def main(argv=None) -> dict:
    import shlex
    import sys
    args = build_parser().parse_args(argv)
    args.command_line = shlex.join(["robostrich-robustness"] + list(sys.argv[1:] if argv is None else argv))
    evaluated = [load_evaluated(args.policy, "policy")]
    domain = evaluated[0].domain
    robot = dataclasses.replace(domain, sent_actions=0)  # what each policy observes may differ, not the robot
    if args.compare:
        evaluated.append(load_evaluated(args.compare, "compare"))
        if dataclasses.replace(evaluated[1].domain, sent_actions=0) != robot:
            raise ValueError(f"--compare {args.compare} is a policy of {evaluated[1].domain.describe()}, "
                             f"not of {robot.describe()}")
    if args.lookup and domain.lookup_table() is not None:
        evaluated.append(lookup_evaluated(robot))
    _check_out(args.out)
    results = measure(evaluated, domain, args.scales, args.num_targets, progress=not args.no_progress)
    report = summary(args, evaluated, results, domain)
    atomic_files.write_json(os.path.join(args.out, "robustness.json"), report)
    robustness_figure.plot(report, os.path.join(args.out, "robustness.png"))
    print("\n".join(summary_lines(report)), flush=True)
    print(f"wrote {args.out}/robustness.json, robustness.png", flush=True)
    return report


def cli(argv=None) -> int:
    """Console script `robostrich-robustness`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-robustness", argv)


if __name__ == "__main__":
    import sys
    sys.exit(cli())
