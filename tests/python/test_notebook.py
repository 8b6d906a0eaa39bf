"""examples/paper.ipynb executed as a reader would run it (nbclient, the
python3 kernel), its last cell's figures checked against the paper's
(Lo Feudo et al. 2020: Table 2, Fig. 5 and 10, Section 4) within the
bands tests/test_paper.cpp uses, and against invariants of the studies.

Run by CTest (python_notebook) with PYTHONPATH=<build>/python and
VINES_SOURCE_DIR=<checkout>; needs Debian's python3-nbclient and
python3-ipykernel (tools/setup.sh all)."""

import json
import os

import nbclient
import nbformat
import pytest

SOURCE = os.environ["VINES_SOURCE_DIR"]
NOTEBOOK = os.path.join(SOURCE, "examples", "paper.ipynb")


@pytest.fixture(scope="module")
def executed():
    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": os.path.dirname(NOTEBOOK)}})
    client.execute()  # raises CellExecutionError naming the cell on any error
    return nb


@pytest.fixture(scope="module")
def measured(executed):
    last = [c for c in executed.cells if c.cell_type == "code"][-1]
    text = "".join(o.text for o in last.outputs if o.output_type == "stream" and o.name == "stdout")
    return json.loads(text)


def test_every_figure_is_drawn(executed):
    images = [o for c in executed.cells if c.cell_type == "code" for o in c.outputs
              if o.output_type == "display_data" and "image/png" in o.data]
    assert len(images) == 7  # Fig. 5, 6, 7, 8, 9, 10 and Table 2's grids


def test_reference_runs_match_the_paper(measured):
    # Table 2's reference case (devices at rest), test_paper.cpp's bands.
    assert measured["rest_tmd"]["x_r"] == pytest.approx(13.1, abs=1.0)
    assert measured["rest_tmd"]["E_r"] == pytest.approx(77.5, abs=1.5)
    assert measured["rest_vines"]["x_r"] == pytest.approx(29.2, abs=2.5)
    assert measured["rest_vines"]["E_r"] == pytest.approx(67.2, abs=2.5)
    assert measured["vines_contacts"] == 18  # docs/model.md's time scales


def test_devices_reduce_the_response(measured):
    peak, ee = measured["fig6_peak_top_m"], measured["fig8_elastic_energy_Js"]
    for device in ("TMD", "VI NES"):
        assert peak[device] < peak["bare"]
        assert ee[device] < ee["bare"]
        assert measured["fig9_floors_reduced"][device] == 10  # every floor's peak


def test_clearance_optimum_is_the_papers(measured):
    assert measured["beta_opt"] == pytest.approx(1.35, abs=0.025)
    assert measured["beta_opt_x_r_pct"] == pytest.approx(measured["rest_vines"]["x_r"], abs=1e-9)


def test_initial_condition_statistics(measured):
    vi, tmd = measured["ic_vines"], measured["ic_tmd"]
    assert vi["runs"] == 1089 and tmd["runs"] == 1089
    # VI NES: 26.0 +- 4.3 % and 60.5 +- 7.4 % in the paper.
    assert vi["x_r_mean"] == pytest.approx(26.0, abs=1.0)
    assert vi["x_r_sd"] == pytest.approx(4.3, abs=1.0)
    assert vi["E_r_mean"] == pytest.approx(60.5, abs=1.5)
    assert vi["E_r_sd"] == pytest.approx(7.4, abs=1.5)
    # TMD: the paper does not state its grid; E_r 76.2 +- 4.5 % is matched,
    # x_r's mean lies within the paper's spread (17.7 +- 6.0 %).
    assert tmd["E_r_mean"] == pytest.approx(76.2, abs=1.5)
    assert abs(tmd["x_r_mean"] - 17.7) <= 6.0
    # Initial conditions cost the VI NES on average (the paper's finding).
    assert vi["x_r_mean"] < measured["rest_vines"]["x_r"]


def test_damage_detunes_the_tmd_not_the_vines(measured):
    negative = measured["damage_tmd_negative_eta"]
    assert negative, "the detuned TMD should amplify the response somewhere"
    assert min(negative) >= 0.85 and max(negative) <= 0.96  # paper: near 0.90-0.95
    assert measured["damage_vines_min_x_r_pct"] > 5.0  # paper: near or above 8 %
