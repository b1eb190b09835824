"""The loops over designs that make a mechanism dict per design (``synth finger-design``)
on the fast path of :mod:`mechsyn.synthesis.templates`: the same evaluations, forces and
designs as parsing each dict (the general path, recorded here by turning the template
off)."""

import copy

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.io import mechanism_from_dict, mechanism_to_dict
from mechsyn.synthesis.finger import cases
from mechsyn.synthesis.finger import evaluation as E
from mechsyn.synthesis.finger.modes import _peaks, redraw
from mechsyn.synthesis.templates import DictTemplate


@pytest.fixture(scope="module")
def case():
    return cases.load_case(ms.examples.path("finger_design_case"))


def _general(monkeypatch):
    monkeypatch.setattr(E, "_template", lambda case, d: None)


def _compare(a, b):
    assert (a.feasible, a.reason) == (b.feasible, b.reason)
    if a.q is None:
        return
    assert np.allclose(a.q, b.q, rtol=0, atol=1e-12)
    assert a.error_rms == pytest.approx(b.error_rms, rel=1e-12, abs=1e-12)
    for k in a.paths:
        assert np.allclose(a.paths[k], b.paths[k], rtol=0, atol=1e-12)


def test_finger_designs_evaluate_and_load_as_parsed(case, monkeypatch):
    rng = np.random.default_rng(3)
    lo, hi = (np.array([v.bounds[i] for v in case.variables]) for i in (0, 1))
    dicts = []
    for x in rng.uniform(lo, hi, size=(30, len(lo))):
        d = E.apply_design(case, x, ("S",))
        dicts.append(d)
        r = redraw(case, d, {"S": 30.0})  # the underactuated mode: every point moves, the tip's load too
        if r is not None:
            dicts.append(r)
    fast = [E.evaluate_drawn(case, d) for d in dicts]
    assert E._template(case, dicts[0]).usable
    _general(monkeypatch)
    slow = [E.evaluate_drawn(case, d) for d in dicts]
    n = 0
    for a, b in zip(fast, slow):
        _compare(a, b)
        if a.q is not None:
            n += 1
            pa, pb = _peaks(a.system, a.q, case), _peaks(b.system, b.q, case)
            assert pa[2] == pb[2] and np.allclose(pa[:2], pb[:2], rtol=1e-12)
    assert n >= 10


@pytest.mark.slow
def test_finger_design_same_seed_same_design_on_both_paths(case, monkeypatch):
    from mechsyn.synthesis.finger.design import design_finger

    new = design_finger(case, seed=0, time_limit=600).to_dict()
    _general(monkeypatch)
    old = design_finger(case, seed=0, time_limit=600).to_dict()

    def same(u, v, where):
        if isinstance(u, dict):
            assert set(u) == set(v), where
            for k in u:
                if k != "seconds":
                    same(u[k], v[k], f"{where}.{k}")
        elif isinstance(u, (list, tuple)) and u and not isinstance(u[0], (int, float)):
            assert len(u) == len(v), where
            for i, (a, b) in enumerate(zip(u, v)):
                same(a, b, f"{where}[{i}]")
        elif isinstance(u, (int, float, list, tuple, np.ndarray)) and not isinstance(u, bool):
            assert np.allclose(np.asarray(u, float), np.asarray(v, float), rtol=1e-12, atol=1e-12,
                               equal_nan=True), where
        else:
            assert u == v, where
    same(old, new, "result")


def test_template_fills_numbers_and_refuses_what_the_reader_would_read_otherwise():
    d = mechanism_to_dict(ms.examples.load("two_phalanx_vll_000"))
    tpl = DictTemplate(d, "<test>")
    assert tpl.usable
    moved = copy.deepcopy(d)
    moved["joints"][2]["point"] = [9, 47]
    moved["points"]["tip"]["at"] = [1.0, 71.0]
    m, ref = tpl.mechanism(moved), mechanism_from_dict(moved, "<test>")
    assert all(np.array_equal(a.point, b.point) for a, b in zip(m.joints, ref.joints))
    assert m.attrs == ref.attrs and m.points["tip"].at.tolist() == [1.0, 71.0]
    other = copy.deepcopy(d)
    other["joints"][0]["actuated"] = True  # another structure
    bad = copy.deepcopy(d)
    bad["joints"][1]["point"] = [0, float("nan")]
    flag = copy.deepcopy(d)
    flag["joints"][1]["point"] = [True, 40]
    zero = copy.deepcopy(d)
    zero["joints"][6]["axis"] = [0, 0]
    for e in (other, bad, flag, zero):
        assert tpl.mechanism(e) is None  # parsed instead: the reader's answer or message
    pinned = copy.deepcopy(d)
    pinned["joints"][2]["point"] = [0, 40]  # C on B: the distal phalanx has zero length
    with pytest.raises(ms.MechsynInputError, match="zero length") as reader:
        mechanism_from_dict(pinned, "<test>")
    with pytest.raises(ms.MechsynInputError) as filled:
        tpl.mechanism(pinned)
    assert str(filled.value) == str(reader.value)
