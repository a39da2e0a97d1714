"""Tresca onset on a small level (studies/validation/tresca.py): a block
sheared on a flat reaches exactly the bound times the area, and a strip
pulled along a flat (load control: only the friction holds its slide)
slides over F/μ less a shear-lag offset of the order of its thickness."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

STUDY = Path(__file__).resolve().parents[1] / "studies" / "validation" / "tresca.py"


@pytest.fixture(scope="module")
def study():
    spec = importlib.util.spec_from_file_location("tresca_study", STUDY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_sheared_block_reaches_the_bound_times_the_area_exactly(study):
    record = study.run_block()
    assert record["area"] == pytest.approx(1.0, rel=1e-14)
    Q, sliding = np.array(record["Q"]), np.array(record["sliding"])
    full = sliding == record["nodes"]
    assert full.any() and not full[1]          # sticks first, slides at the end
    np.testing.assert_allclose(Q[full], 2.0 * record["area"], rtol=1e-10)
    assert np.all(Q[~full] < 2.0)              # below the bound while part sticks


def test_the_slip_zone_of_a_pulled_strip_is_F_over_mu_less_a_shear_lag(study):
    record = study.run_strip((200, 10))
    for row in record["rows"][1:]:             # F = 2 … 8: past one thickness of slip
        offset = (row["F"] / 1.0 - row["slip_length"]) / 0.5
        assert 0.6 - row["cell"] / 0.5 <= offset <= 0.75 + row["cell"] / 0.5
