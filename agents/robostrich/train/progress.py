"""robostrich-train's progress bars: one over every run's control steps, one over the final
evaluations' episodes, and the stand-in a worker process forwards its progress through."""
import sys
from collections import deque

import numpy as np
from tqdm import tqdm

from agents.robostrich.evaluate.evaluation import outcome_text


def lesson_text(run) -> str:
    """'2/3': the lesson a run is in, for the progress bar."""
    return f"{run.lesson_index + 1 if not run.done else len(run.plan)}/{len(run.plan)}"


class Progress:
    """tqdm bar over all control steps of all runs: steps/s, run, lesson, recent return and
    success, with a line above it per periodic evaluation; then a second bar over the final
    evaluations' episodes (``evaluations`` of them)."""

    def __init__(self, total: int, enabled: bool = True, evaluations: int = 0):
        self.bar = self.eval_bar = None
        self.enabled, self.evaluations = enabled, evaluations
        if enabled:
            self.bar = tqdm(total=total, unit="step", dynamic_ncols=True, smoothing=0.05)
        self.returns = deque(maxlen=20)
        self.successes = deque(maxlen=50)

    def skip(self, n: int):
        """n steps a resumed run had already taken: counted as done, not into the steps/s."""
        if self.bar is not None and n:
            self.bar.n += n
            self.bar.last_print_n += n
            self.bar.initial += n
            self.bar.refresh()

    def evaluated(self, n: int = 1):
        """n more episodes of the final evaluations (the bar appears with the first)."""
        if not self.enabled or not self.evaluations:
            return
        if self.eval_bar is None:
            self.eval_bar = tqdm(total=self.evaluations, desc="final evaluation", unit="episode",
                                 dynamic_ncols=True, position=1)
        self.eval_bar.update(n)

    def on_episode(self, record):
        self.returns.append(record["return"])
        self.successes.append(float(record["success"]))

    def update(self, n, run):
        self.advance(n, run.name, lesson_text(run))

    def advance(self, n, label: str, lesson: str):
        """n more steps of run `label`, now in `lesson` (also what worker processes report)."""
        if self.bar is None:
            return
        self.bar.update(n)
        self.bar.set_postfix({"run": label, "lesson": lesson,  # in this order (keywords would be sorted)
                              "return": f"{np.mean(self.returns) if self.returns else float('nan'):.1f}",
                              "reached": f"{np.mean(self.successes) * 100 if self.successes else float('nan'):.0f}%"},
                             refresh=False)

    def periodic(self, label: str, record: dict):
        """One line above the bar for a periodic held-out evaluation of run ``label`` (its evals.jsonl record)."""
        if self.bar is None or "success_rate" not in record["summary"]:
            return
        self.bar.write(f"{label} at {record['env_steps']:,} control steps: held-out "
                       f"{outcome_text('heldout', record['summary']).strip()}", file=sys.stderr)

    def reset_window(self):
        self.returns.clear()
        self.successes.clear()

    def close(self, cleared: bool = False):
        """Close the bars (``cleared``: wipe them, the command stopped early)."""
        for bar in (self.eval_bar, self.bar):
            if bar is not None:
                bar.leave = bar.leave and not cleared
                bar.close()


class QueueProgress:
    """Stands in for `Progress` inside a worker: forwards steps and episodes to the parent's bar."""

    def __init__(self, queue, label):
        self.queue, self.label = queue, label

    def on_episode(self, record):
        self.queue.put(("episode", self.label, {"return": record["return"], "success": record["success"]}))

    def update(self, n, run):
        self.queue.put(("steps", self.label, (n, lesson_text(run))))

    def reset_window(self):
        pass

    def evaluated(self, n: int = 1):
        self.queue.put(("evaluated", self.label, n))

    def periodic(self, label: str, record: dict):
        self.queue.put(("periodic", label, record))
