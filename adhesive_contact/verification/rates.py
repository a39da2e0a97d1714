"""Observed rates of convergence: the slope of log(error) against
log(size), by least squares over the levels (:func:`fitted_rate`,
:func:`rates`) and between consecutive levels (:func:`pairwise_rates`).
A study of a scalar quantity Q adds its error |Q_h − Q_ref| (key
``err_q``, rate ``"Q"``), fitted the same way.
For a study in h the size is the mesh size h, in k the step k, in hk
(both halved together) h."""

import math

import numpy as np

#: the error keys of a level's record and the names of their rates
ERRORS = (("u", "err_u"), ("beta", "err_beta"), ("E", "E"))
#: the record key of a scalar quantity's error and the name of its rate
QUANTITY_ERROR = ("Q", "err_q")


def fitted_rate(sizes, errors):
    """Least-squares slope of log(error) against log(size) (NaN if < 2 usable)."""
    sizes, errors = np.asarray(sizes, float), np.asarray(errors, float)
    ok = (sizes > 0) & (errors > 0) & np.isfinite(errors)
    if ok.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(sizes[ok]), np.log(errors[ok]), 1)[0])


def size_key(param):
    """The record key of a level's size in a study of ``param``."""
    return "k" if param == "k" else "h"


def rates(records, param, quantity=False):
    """Least-squares rates {"u", "beta", "E"} against h (or k for a k-study);
    with ``quantity`` also "Q", that of the records' ``err_q``."""
    sizes = [r[size_key(param)] for r in records]
    errors = ERRORS + ((QUANTITY_ERROR,) if quantity else ())
    return {name: fitted_rate(sizes, [math.nan if r[key] is None else r[key]
                                      for r in records]) for name, key in errors}


def pairwise_rates(records, param, key="E"):
    """Rates between consecutive levels (the first is None)."""
    size = size_key(param)
    out = [None]
    for a, b in zip(records[:-1], records[1:]):
        if a[key] is not None and b[key] is not None and a[key] > 0 and b[key] > 0:
            out.append(float(np.log(a[key] / b[key]) / np.log(a[size] / b[size])))
        else:
            out.append(None)
    return out
