"""The engine protocol: every planar example names the engine that ran; events are typed
records whose JSON form is that of the former event dictionaries."""

import json

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics import engines
from mechsyn.kinematics.analysis import simulate
from mechsyn.kinematics.engines import PLANAR_ENGINES, Engine, first_sweep
from mechsyn.kinematics.sweep import Event, Sweep
from mechsyn.results import to_jsonable

from kinematics_helpers import driven_planar_examples, ex  # noqa: F401


EXAMPLES = driven_planar_examples()


def test_the_planar_engines_in_order():
    assert [e.name for e in PLANAR_ENGINES] == ["regular pass", "tracked chain", "tracked groups", "newton"]
    for e in PLANAR_ENGINES:
        assert isinstance(e.name, str) and callable(e.sweep)


@pytest.mark.parametrize("name,m", EXAMPLES, ids=[n for n, _ in EXAMPLES])
def test_every_example_names_its_engine(name, m):
    """``Simulation.engine`` is the engine that computed the sweep: the first of the list
    that answers, run here by hand on the same inputs."""
    from mechsyn.kinematics.analysis import cached_plan

    j = next(j for j in m.joints if j.actuated)
    try:
        kp = cached_plan(m, inputs=(j.id,))
        d = next(d for d in kp.system.drivers if d.joint == j.id)
        x = np.linspace(0.0, 90.0, 19) if j.type == "R" else d.assembled + np.linspace(-0.02, 0.02, 9)
        S = m.simulate({j.id: x})
    except MechsynInputError as e:  # the file needs all its inputs (or is refused): said in one line
        assert str(e)
        pytest.skip(f"{name}: refused with one input")
    assert S.engine in {e.name for e in PLANAR_ENGINES}
    assert S.sweep.engine == S.engine
    assert S.to_dict()["engine"] == S.engine
    plan, U = kp.groups, S.sweep.inputs
    tried = [e.name for e in PLANAR_ENGINES if e.sweep(S.system, plan, U, S.sweep.speeds) is not None]
    assert tried and tried[0] == S.engine
    assert (plan is None) == (S.engine == "newton")


def test_an_engine_that_declines_passes_to_the_next(ex):
    class Never:
        name = "never"

        def sweep(self, system, plan, inputs, speeds, *, change_points="keep", progress=None):
            return None

    never: Engine = Never()
    from mechsyn.kinematics.analysis import cached_plan

    kp = cached_plan(ex("kinematics/crank_rocker.yaml"), inputs=("A",))
    U = np.radians(np.linspace(0, 360, 37))[:, None]
    sw = first_sweep((never,) + PLANAR_ENGINES, kp.system, kp.groups, U, np.ones(1))
    assert isinstance(sw, Sweep) and sw.engine == "regular pass"
    assert first_sweep((never,), kp.system, kp.groups, U, np.ones(1)) is None
    # a Peaucellier cell whose rhombus passes change points: the regular pass declines, the
    # tracked chain answers (a textbook four-bar's dead points the regular pass goes through)
    kp = cached_plan(ex("kinematics/peaucellier.yaml"), inputs=("E",))
    assert engines.RegularPass().sweep(kp.system, kp.groups, U, np.ones(1)) is None
    assert first_sweep(PLANAR_ENGINES, kp.system, kp.groups, U, np.ones(1)).engine == "tracked chain"
    kp = cached_plan(ex("textbook/fourbar.yaml"), inputs=("A",))
    assert first_sweep(PLANAR_ENGINES, kp.system, kp.groups, U, np.ones(1)).engine == "regular pass"


def test_events_are_typed_and_their_json_is_the_former_dicts(ex):
    s = simulate(ex("textbook/fourbar.yaml"), {"A": np.arange(0.0, 361.0, 1.0)})
    assert s.events and all(isinstance(e, Event) for e in s.events)
    kinds = [e.kind for e in s.events]
    assert kinds.count("dead point") == 2
    d = json.loads(json.dumps(to_jsonable(s.to_dict())))
    for e, j in zip(s.events, d["events"]):
        assert list(j) == list(e.to_dict()) and j["kind"] == e["kind"] == e.kind
        assert set(j) <= {"index", "kind", "input", "group", "crossed", "message", "before_sweep"}
        assert isinstance(j["input"], dict) and set(j["input"]) == {"A"}
    assert d["events"][0]["kind"] == "dead point" and d["events"][0]["group"] == "B-C-D"


def test_event_json_keys():
    e = Event(2, "limit", "too long", joint="V", value=3.5)
    assert e.to_dict() == {"index": 2, "kind": "limit", "joint": "V", "value": 3.5, "message": "too long"}
    e = Event(0, "singular", "folded", input=[0.1], crossed=False)
    assert list(e.to_dict()) == ["index", "kind", "input", "crossed", "message"]
    assert e.get("group") is None and e["crossed"] is False


def test_every_engine_by_its_name_and_a_decline_in_one_line(ex):
    """``ENGINES`` names every engine once; ``method=NAME`` runs that engine alone (any of
    ``regular_pass``, ``regular-pass``, ``Regular Pass``); one that cannot treat the
    mechanism raises ``EngineDeclined`` (a ``MechsynInputError``) saying why in one line,
    an unknown name lists the names."""
    from mechsyn.errors import EngineDeclined, MechsynError
    from mechsyn.kinematics import ENGINES
    from mechsyn.kinematics.engines import engine_named

    names = [e.name for e in ENGINES]
    assert len(set(names)) == len(names) and names[-1] == "spatial"
    m = ex("kinematics/crank_rocker.yaml")
    for spelled in ("regular_pass", "regular-pass", "Regular Pass"):
        assert engine_named(spelled) is ENGINES[0]
        assert m.simulate(A=(0, 90, 45), method=spelled).engine == "regular pass"
    with pytest.raises(EngineDeclined) as err:
        simulate(ex("kinematics/cam_roller.yaml"), {"O": np.array([0.0, 10.0])}, method="tracked groups")
    assert isinstance(err.value, MechsynError) and isinstance(err.value, MechsynInputError)
    assert err.value.engine == "tracked groups" and "\n" not in str(err.value)
    assert "does not split into drivers and dyads" in err.value.why
    with pytest.raises(EngineDeclined, match="takes planar mechanisms"):
        simulate(ex("spatial/bennett_tilted.yaml"), {"R1": np.array([0.0])}, method="newton")
    with pytest.raises(MechsynInputError, match="unknown method 'magic'.*regular pass, tracked chain"):
        m.simulate(A=(0, 90, 45), method="magic")


def test_one_motion_for_every_engine(ex):
    """The planar and the spatial results are one ``Motion``: the same fields, methods and
    JSON keys (``to_dict``), a table for each (2-D and 3-D points)."""
    import mechsyn as ms
    from mechsyn.kinematics import Motion

    m = ex("kinematics/crank_rocker.yaml")
    planar = m.simulate(A=(0, 90, 30))
    spatial = m.simulate(A=(0, 90, 30), method="spatial")
    bennett = ms.simulate(ms.examples.load("bennett"), {"R1": ms.input_grid(0, 90, 30)})
    common = {"mechanism", "input", "inputs", "assembled", "points", "links", "working_ranges", "events",
              "method", "engine", "notes"}
    for s in (planar, spatial, bennett):
        assert isinstance(s, Motion) and common <= set(s.to_dict())
        assert s.working_ranges() and s.point(next(iter(s.points))).shape[0] == 4
        assert all(isinstance(e, Event) for e in s.events)
    assert np.abs(spatial.point("M")[:, :2] - planar.point("M")).max() < 1e-9
    assert spatial.inputs["A"].tolist() == planar.inputs["A"].tolist()
    pd = pytest.importorskip("pandas")
    cols = spatial.to_pandas().columns
    assert {"M_x", "M_y", "M_z", "M_vz"} <= set(cols) and isinstance(planar.to_pandas(), pd.DataFrame)
