"""A convergence study says when its rates are not to be trusted:
errors that do not decrease, pairwise rates that scatter, a fine
reference too close to the finest level."""

from adhesive_contact.studies.convergence import trust


def document(errors, rates, param="h", reference=None):
    levels = [{"level": i, "E": e, "rate_E": r} for i, (e, r) in enumerate(zip(errors, rates))]
    return {"param": param, "levels": levels, "reference": reference or {"kind": "exact"}}


def test_a_clean_first_order_study_has_no_warning():
    assert trust(document([8e-3, 4e-3, 2e-3, 1e-3], [None, 1.0, 1.0, 1.0])) == []


def test_errors_that_grow_and_rates_that_scatter_are_named():
    # the case met in a trial: a fitted 0.50 from pairwise rates including -0.51
    warnings = trust(document([8e-3, 2e-3, 2.85e-3, 1e-3], [None, 2.0, -0.51, 1.51]))
    assert warnings[0] == "E does not decrease from level 1 to 2 (0.002 to 0.00285)"
    assert warnings[1].startswith("the pairwise rates of E scatter from -0.51 to 2.00")
    assert len(warnings) == 2


def test_a_fine_reference_too_close_is_named():
    near = {"kind": "fine", "ref_h": 1, "ref_k": 0}
    warnings = trust(document([8e-3, 4e-3, 2e-3], [None, 1.0, 1.0], "h", near))
    assert warnings == ["the fine reference is refined only 1 more times than the finest "
                        "level: its own error biases the finest errors (use --ref-h 2 or more)"]
    assert trust(document([8e-3, 4e-3, 2e-3], [None, 1.0, 1.0], "h",
                          {"kind": "fine", "ref_h": 2, "ref_k": 0})) == []
