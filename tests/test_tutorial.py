"""docs/tutorial.ipynb runs top to bottom, as a reader's kernel runs it: a tutorial that stops running
is a failing test. Its training cell is cut to seconds here (ROBOSTRICH_TUTORIAL_QUICK=1); every
other cell runs what a reader runs. The notebook is kept in git without outputs."""
import pathlib

import pytest

TUTORIAL = pathlib.Path(__file__).resolve().parents[1] / "docs" / "tutorial.ipynb"


def _outputs(cell) -> list:
    return [output for output in cell.get("outputs", [])]


def test_the_tutorial_is_kept_without_outputs():
    nbformat = pytest.importorskip("nbformat", reason="nbformat is in the test extra")
    notebook = nbformat.read(TUTORIAL, as_version=4)
    nbformat.validate(notebook)
    kept = [i for i, cell in enumerate(notebook.cells)
            if cell.cell_type == "code" and (cell.outputs or cell.execution_count is not None)]
    assert not kept, f"cells {kept} keep outputs: clear them before committing"


@pytest.mark.long
def test_the_tutorial_runs_top_to_bottom(tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat", reason="nbformat is in the test extra")
    nbclient = pytest.importorskip("nbclient", reason="nbclient is in the test extra")
    monkeypatch.setenv("ROBOSTRICH_TUTORIAL_QUICK", "1")
    notebook = nbformat.read(TUTORIAL, as_version=4)
    nbclient.NotebookClient(notebook, timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in _outputs(cell)]
    text = "".join(output.get("text", "") for output in outputs if output.output_type == "stream")
    kinds = [kind for output in outputs for kind in output.get("data", {})]
    assert kinds.count("image/png") >= 4, kinds  # the frame, the errors, the learning curve, the two routings
    assert "application/vnd.jupyter.widget-view+json" in kinds, kinds  # the recording, inline
    assert "targets reached" in text and "held-out success" in text and "ventral_from_base" in text, text
    assert (tmp_path / "tutorial_out" / "track.rrd").stat().st_size > 0
