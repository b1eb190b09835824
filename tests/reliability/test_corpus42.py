"""The command-line findings of issue 42 (hostile inputs, third pass), kept as tests: each
gave a traceback, a hang, unbounded memory or a believed forgery on the code before; each
must now be one line naming the file and field with exit status 2 (or, for a signal, the
best result known kept). Special files for every command: test_special_files.py."""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path

import numpy as np
import pytest
import yaml

from mechsyn.errors import MechsynInputError

from test_corpus import FOURBAR, one_error_line

ROOT = Path(__file__).resolve().parents[2]
PATH_CASES = ROOT / "examples" / "synthesis" / "path_cases_public.json"
CASE = "P2_kk5_timing"


def _exit2(run_cli, *args) -> str:
    code, out, err = run_cli(*args)
    assert code == 2, (code, out[-300:], err[-300:])
    return one_error_line(err)


# ------------------------------------------------------------------ synth curve targets
@pytest.mark.parametrize("text, words", [
    ('{"points": [[0, 0], [1, 0], [1, 1]], "points": [[0, 0], [2, 0], [2, 2]]}', "'points' is written twice"),
    ('{"points": [[0, 0], [1, 0], [1, 1]], "closed": "false"}', "closed: must be true or false, not str"),
    ('{"points": [[0, 0], [1, 0], [true, 1]]}', "points[2]: expected [x, y]"),
    ('{"points": [[0, 0], [1, 0], [1, 1]], "colsed": true}', "unknown key 'colsed'"),
    ('{"points": [[0, 0], [1, 0], [1, Infinity]]}', "Infinity is not a number"),
    ("[" * 10_000 + "]" * 10_000, "nested more than 64 levels"),
])
def test_json_target_readers(run_cli, tmp_path, text, words):
    f = tmp_path / "t.json"
    f.write_text(text)
    msg = _exit2(run_cli, "synth", "curve", f)
    assert "t.json" in msg and words in msg


def test_a_target_larger_than_its_cap_is_refused(tmp_path, monkeypatch):
    from mechsyn.synthesis.curves import target

    f = tmp_path / "t.csv"
    f.write_text("0,0\n" * 1000)
    monkeypatch.setattr(target, "MAX_TARGET_BYTES", 100)
    with pytest.raises(MechsynInputError, match="of 4,000 bytes is larger than the limit of 100") as err:
        target.read_target(f)
    assert "MECHSYN_LIMIT_FILE_BYTES" not in str(err.value)  # a fixed cap of its kind, not that limit


# ------------------------------------------------------------------ Pyslvs
def test_pyslvs_forty_thousand_links_in_one_joint_refused_while_parsing(run_cli, tmp_path, monkeypatch):
    """The link limit applies as names are read (at the 2,001st), with names in a set: the
    work done is bounded by the limit, not by the 40,000 names (asserted on the column
    where the parser stopped, not on time)."""
    import mechsyn.io.pyslvs as pyslvs

    names = [f"l{i}" for i in range(40_000)]
    text = "M[J[R, P[0, 0], L[ground, " + ", ".join(names) + "]]]"
    f = tmp_path / "big.pyslvs"
    f.write_text(text)
    looked_up = []
    real = pyslvs._Parser._count_link
    monkeypatch.setattr(pyslvs._Parser, "_count_link", lambda self, name: looked_up.append(name) or real(self, name))
    msg = _exit2(run_cli, "convert", f, "-o", tmp_path / "o.yaml")
    assert "more than the limit of 2,000 links" in msg and "MECHSYN_LIMIT_LINKS" in msg
    column = int(msg.split("(column ")[1].split(")")[0])
    assert column == text.index("l1999,") + 1  # the 2,001st link (ground counts)
    assert len(looked_up) == 2_001  # ground, l0 ... l1999: the 2,001st link is refused, l2000 ... never counted
    assert not (tmp_path / "o.yaml").exists()


def test_pyslvs_link_names_are_checked_in_constant_time(monkeypatch):
    """Above the limit (raised), 40,000 names in one joint are read: a repeated name is found
    through a mapping (a list made this quadratic, 47 s)."""
    from mechsyn.io.pyslvs import parse_expression
    from mechsyn.limits import set_limit

    set_limit("links", 100_000)
    try:
        m = parse_expression("M[J[R, P[0, 0], L[ground, " + ", ".join(f"l{i}" for i in range(40_000)) + "]]]")
        assert len(m.joints[0].links) == 40_001
        with pytest.raises(MechsynInputError, match="listed twice"):
            parse_expression("M[J[R, P[0, 0], L[ground, " + ", ".join(f"l{i}" for i in range(40_000)) + ", l7]]]")
    finally:
        set_limit("links", None)


# ------------------------------------------------------------------ curve database
@pytest.fixture(scope="module")
def small_db(tmp_path_factory):
    from mechsyn.synthesis.curves.database import build_database

    d = tmp_path_factory.mktemp("db")
    build_database(d, max_links=4, per_topology=30)
    return d


def _npy(a: np.ndarray) -> bytes:
    b = io.BytesIO()
    np.save(b, a)
    return b.getvalue()


def _rewrite(f: Path, members: dict[str, bytes]) -> None:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        for k, v in members.items():
            zf.writestr(f"{k}.npy", v)
    f.write_bytes(buf.getvalue())


@pytest.mark.parametrize("damage, words", [
    ("narrow", "descriptors: shape (30, 3), expected (30, 20)"),
    ("nan", "descriptors holds values that are not finite"),
    ("rows", "header's shape (100000000000, 20) does not match"),
    ("declared", "the archive declares"),
    ("object", "dtype object"),
])
def test_damaged_curve_database(run_cli, small_db, tmp_path, damage, words, monkeypatch):
    import shutil

    db = tmp_path / "db"
    shutil.copytree(small_db, db)
    f = sorted(db.glob("*.npz"))[0]
    with np.load(f) as z:
        data = {k: z[k] for k in z.files}
    members = {k: _npy(v) for k, v in data.items()}
    if damage == "narrow":
        members["descriptors"] = _npy(data["descriptors"][:, :3])
    elif damage == "nan":
        members["descriptors"] = _npy(np.full_like(data["descriptors"], np.nan))
    elif damage == "rows":  # np.load would try to allocate 7.3 TiB
        members["descriptors"] = members["descriptors"].replace(
            str(data["descriptors"].shape).encode(), b"(100000000000, 20)")
    elif damage == "object":
        members["ranges"] = members["ranges"].replace(b"'<f4'", b"'|O' ")
    _rewrite(f, members)
    if damage == "declared":  # the zip's own size field says 1 TB for a small member
        raw = bytearray(f.read_bytes())
        with zipfile.ZipFile(f) as zf:
            info = zf.getinfo("descriptors.npy")
        cd = raw.rfind(b"PK\x01\x02" + raw[4:6], 0)  # any central record; patch the one of descriptors
        cd = bytes(raw).find(b"descriptors.npy", info.header_offset + 30 + len("descriptors.npy")) - 46
        raw[cd + 24:cd + 28] = (10 ** 12 % 2 ** 32).to_bytes(4, "little")
        f.write_bytes(bytes(raw))
    target = tmp_path / "t.csv"
    target.write_text("0,0\n1,0\n1,1\n0,1\n")
    msg = _exit2(run_cli, "synth", "curve", target, "--database", db, "--max-links", "4")
    assert f.name in msg and "the curve database file is damaged" in msg and words in msg, msg
    assert "mechsyn curves build --links 4" in msg


# ------------------------------------------------------------------ synth path checkpoint
@pytest.fixture(scope="module")
def genuine_checkpoint(tmp_path_factory):
    from mechsyn.cli.main import main
    from mechsyn.synthesis.cases import load_cases
    from mechsyn.synthesis.optimize import synthesize_path

    ck = tmp_path_factory.mktemp("ck") / "run.ckpt.json"
    assert main(["synth", "path", str(PATH_CASES), "--case", CASE, "--seed", "3", "--restarts", "3",
                 "--time-limit", "6", "--checkpoint", str(ck)]) == 0
    key = json.loads(ck.read_text())["key"]
    case = next(c for c in load_cases(PATH_CASES) if c.id == CASE)
    genuine = synthesize_path(case, seed=3, restarts=3, time_limit=60, checkpoint=ck, resume=True,
                              target_error=key["target_error"], optimizer=key["optimizer"], options=key["options"])
    assert genuine.resumed >= 1  # restart 0 at least (a later one is not run once one reached the target)
    return ck, genuine


def _forged(genuine_checkpoint, tmp_path, change) -> Path:
    ck, _ = genuine_checkpoint
    data = json.loads(ck.read_text())
    change(data)
    f = tmp_path / "forged.ckpt.json"
    f.write_text(json.dumps(data))
    return f


def _resume(run_cli, f):
    return run_cli("synth", "path", PATH_CASES, "--case", CASE, "--seed", "3", "--restarts", "3",
                   "--time-limit", "60", "--resume", f, "--json")


def test_a_forged_fitness_is_not_believed(run_cli, genuine_checkpoint, tmp_path, monkeypatch):
    """A finished restart claiming fitness -5 is evaluated again: the result and the printed
    restart errors are the genuine ones."""
    _, genuine = genuine_checkpoint

    def lie(d):
        for r in d["finished"].values():
            r["fitness"] = -5.0

    code, out, err = _resume(run_cli, _forged(genuine_checkpoint, tmp_path, lie))
    assert code == 0, err
    res = json.loads(out)
    assert res["error"] == pytest.approx(genuine.error, rel=1e-9)
    assert -5.0 not in res["restart_errors"] and min(res["restart_errors"]) >= 0
    assert res["restart_errors"] == pytest.approx(genuine.restart_errors, rel=1e-9)


@pytest.mark.parametrize("change, words", [
    (lambda d: d["finished"]["0"].update(x=[1e90] * len(d["finished"]["0"]["x"]), fitness=-5.0),
     "outside the case's bounds"),
    (lambda d: d["finished"].update({"-7": d["finished"]["0"]}), "restart index '-7' is not a whole number"),
    (lambda d: d["finished"].update({"99999": d["finished"]["0"]}), "restart index 99999 is outside 0 ... 2"),
    (lambda d: d["finished"]["0"].update(seed=d["finished"]["0"]["seed"] + 1), "finished[0].seed"),
])
def test_a_forged_restart_is_refused(run_cli, genuine_checkpoint, tmp_path, change, words):
    msg = _exit2(run_cli, *["synth", "path", PATH_CASES, "--case", CASE, "--seed", "3", "--restarts", "3",
                            "--time-limit", "60", "--resume", _forged(genuine_checkpoint, tmp_path, change)])
    assert "forged.ckpt.json" in msg and words in msg, msg


# ------------------------------------------------------------------ atlas stream
def test_an_atlas_stream_line_of_ten_thousand_nested_brackets(run_cli, tmp_path):
    stream = tmp_path / "s.jsonl"
    assert run_cli("atlas", "-n", "6", "--stream", stream)[0] == 0
    lines = stream.read_text().splitlines()
    lines[1] = "[" * 10_000 + "]" * 10_000
    stream.write_text("\n".join(lines) + "\n")
    msg = _exit2(run_cli, "atlas", "-n", "6", "--stream", stream)
    assert "s.jsonl:2:" in msg and "nested more than 64 levels" in msg


def test_read_chain_stream_refuses_deep_header(tmp_path):
    from mechsyn.synthesis.chains import read_chain_stream

    f = tmp_path / "s.jsonl"
    f.write_text("[" * 10_000 + "]" * 10_000 + "\n")
    with pytest.raises(MechsynInputError, match="nested more than"):
        read_chain_stream(f)


# ------------------------------------------------------------------ confusable and bidi ids
def _mech(tmp_path, change) -> Path:
    d = json.loads(json.dumps(FOURBAR))
    change(d)
    f = tmp_path / "m.yaml"
    f.write_text(yaml.safe_dump(d, allow_unicode=True))
    return f


@pytest.mark.parametrize("change, words", [
    (lambda d: d["joints"][1].update(id="\u0410"), "the joint id '\u0410' (U+0410) looks like 'A'"),  # Cyrillic A
    (lambda d: d["joints"][1].update(id="\u0391"), "looks like 'A'"),  # Greek Alpha
    (lambda d: d["joints"][1].update(id="B\u0430d"), "mixes the scripts cyrillic, latin"),
    (lambda d: d["joints"][1].update(id="\uff21"), "not in its normal form (NFKC)"),  # fullwidth A
    (lambda d: d["links"].append("\u0441rank"), "mixes the scripts cyrillic, latin"),
])
def test_confusable_ids_are_refused(run_cli, tmp_path, change, words):
    msg = _exit2(run_cli, "analyze", _mech(tmp_path, change))
    assert "m.yaml" in msg and words in msg, msg


@pytest.mark.parametrize("ident", ["P\u03b1", "\u0416", "\u95a2\u7bc0\u3072"])  # Greek alpha in Latin, Cyrillic Zhe, Japanese
def test_ids_in_one_script_or_without_look_alikes_are_accepted(run_cli, tmp_path, ident):
    f = _mech(tmp_path, lambda d: d["joints"][1].update(id=ident))
    assert run_cli("analyze", f, "--json")[0] == 0


def test_visible_text_marks_or_strips_bidi_controls():
    from mechsyn.io.files import visible_text

    name = "gripper\u202e2v\u2066"
    assert visible_text(name) == "gripper2v"
    assert visible_text(name, mark=True) == "gripper<U+202E>2v<U+2066>"


# ------------------------------------------------------------------ URDF numbers
URDF = """<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
<joint name="j1" type="revolute"><parent link="a"/><child link="b"/><origin xyz="{origin}"/><axis xyz="{axis}"/>
<limit {limit} velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="b"/><child link="c"/><origin xyz="1 0 0"/><limit velocity="1"/></joint>
</robot>"""


@pytest.mark.parametrize("origin, axis, lim, words", [
    ("0 0 0", "1e308 0 0", 'lower="-1"', '<axis xyz="1e308 0 0"> holds a number that is not finite or beyond'),
    ("0 0 0", "1e200 1e200 0", 'lower="-1"', '<axis xyz="1e200 1e200 0">'),
    ("0 0 0", "0 0 nan", 'lower="-1"', '<axis xyz="0 0 nan">'),
    ("1e300 0 0", "0 0 1", 'lower="-1"', '<origin xyz="1e300 0 0">'),
    ("1 0", "0 0 1", 'lower="-1"', '<origin xyz="1 0"> is not 3 numbers'),
    ("0 0 0", "0 0 1", 'lower="abc"', '<limit lower="abc"> is not a number'),
])
def test_urdf_numbers_are_refused_with_one_line(run_cli, tmp_path, origin, axis, lim, words):
    f = tmp_path / "r.urdf"
    f.write_text(URDF.format(origin=origin, axis=axis, limit=lim))
    with np.errstate(all="raise"):  # an overflow inside would raise here, not warn
        msg = _exit2(run_cli, "capability", f, "--direction", "1,0,0", "--point", "1,0,0")
    assert "r.urdf" in msg and "joint 'j1'" in msg and words in msg, msg


def test_a_tiny_urdf_axis_is_a_direction(tmp_path):
    from mechsyn.capability.arm_file import load_arm

    f = tmp_path / "r.urdf"
    f.write_text(URDF.format(origin="0 0 0", axis="1e-300 1e-300 0", limit='lower="-1"'))
    arm = load_arm(f)
    assert np.allclose(arm.axes[0], [2 ** -0.5, 2 ** -0.5, 0.0])


def test_the_exact_limit_of_a_block_of_configurations_is_that_of_each():
    """exact_limit_lp solves the configurations as one block-diagonal program: the same
    answers as one program each (and the closed form where it applies)."""
    from mechsyn.capability.measures import _exact_limit_facets, exact_limit_lp

    rng = np.random.default_rng(7)
    J = rng.normal(size=(40, 3, 6))
    J[:5, :, 2:] = 0.0  # rank-deficient ones
    w = rng.uniform(0.5, 2.0, size=6)
    d = np.array([0.3, -1.0, 0.5])
    block = exact_limit_lp(J, w, d)
    one_by_one = np.concatenate([exact_limit_lp(J[k:k + 1], w, d) for k in range(40)])
    assert np.allclose(block, one_by_one, rtol=1e-9, atol=1e-12)
    assert np.allclose(block[5:], _exact_limit_facets(J[5:], np.broadcast_to(w, (35, 6)),
                                                      np.broadcast_to(d / np.linalg.norm(d), (35, 3))), rtol=1e-7)


# ------------------------------------------------------------------ finger-design final checks
def test_a_signal_in_finger_design_final_checks_keeps_the_best_design(run_cli, tmp_path, monkeypatch):
    """Ctrl-C/SIGTERM after the search (in the final checks of the chosen design) wrote
    nothing; now the stage-1 design is written (JSON, --out, checkpoint) and the exit is 130."""
    import mechsyn.synthesis.finger.design as design

    calls = [0]
    real = design._variant

    def variant(*a, **k):
        calls[0] += 1
        if calls[0] == 1:  # the chosen design's final evaluation, after the search
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(design, "_variant", variant)
    case = ROOT / "examples" / "fingers" / "finger_design_case.yaml"
    out, ck = tmp_path / "best.yaml", tmp_path / "run.ckpt.json"
    code, stdout, err = run_cli("synth", "finger-design", case, "--json", "--out", out, "--checkpoint", ck,
                                "--time-limit", "20")
    assert code == 130, err[-400:]
    res = json.loads(stdout)
    assert res["interrupted"] and out.exists() and ck.exists()
    assert any("interrupted during the checks" in n for n in res["notes"])
    best = res["variants"][res["best"]] if isinstance(res.get("best"), int) else res["variants"][0]
    assert best["design"] == best["stage1_design"]  # the best known when the signal came


@pytest.mark.parametrize("message", ["VLL ranges and forces of the stage-1 design", "stage 2: forces"])
def test_a_signal_at_each_phase_after_stage_one_keeps_it(message):
    from mechsyn.synthesis.finger.cases import load_case
    from mechsyn.synthesis.finger.design import design_finger

    case = load_case(ROOT / "examples" / "fingers" / "finger_design_case.yaml")
    case.maxiter, case.force_maxiter = 6, 3

    def progress(state):
        if state.message.startswith(message):
            raise KeyboardInterrupt

    res = design_finger(case, seed=1, time_limit=60, progress=progress)
    assert res.interrupted and res.variants
    v = res.variants[0]
    assert v.design == v.stage1_design and np.isfinite(v.error_rms) and "criterion" in v.forces


# ------------------------------------------------------------------ one schema per shape: wrong types
def _edited(tmp_path, source: Path, change) -> Path:
    """``source`` changed, written into a copy of its folder in ``tmp_path`` (relative paths kept by
    copying the folder)."""
    import shutil

    folder = tmp_path / source.parent.name
    shutil.copytree(source.parent, folder)
    shutil.copytree(source.parent.parent / "textbook", tmp_path / "textbook", dirs_exist_ok=True)
    f = folder / source.name
    data = json.loads(f.read_text()) if f.suffix == ".json" else yaml.safe_load(f.read_text())
    change(data)
    f.write_text(json.dumps(data) if f.suffix == ".json" else yaml.safe_dump(data))
    return f


@pytest.mark.parametrize("source, args, change, words", [
    ("fingers/finger_design_case.yaml", ["synth", "finger-design"],
     lambda d: d.setdefault("optimizer", {}).update(vll_steps=1e308), "optimizer.vll_steps: 1e+308 is outside"),
    ("fingers/finger_design_case.yaml", ["synth", "finger-design"],
     lambda d: d.setdefault("optimizer", {}).update(maxiter="40"), "optimizer.maxiter: expected a whole number"),
    ("fingers/finger_design_case.yaml", ["synth", "finger-design"],
     lambda d: d.update(gravity=[9.81]), "gravity must be one number"),
    ("synthesis/path_cases_public.json", ["synth", "path"], lambda d: d.update(cases=True), "cases must be a list"),
    ("synthesis/path_cases_public.json", ["synth", "path", "--case", CASE],
     lambda d: d["cases"][0]["best_known"].update(value=[1, "a"]), "best_known.value must be one number"),
    ("synthesis/sixbar_path_case.yaml", ["synth", "mechanism"],
     lambda d: d["input"].update(free="false"), "input.free: must be true or false, not str 'false'"),
    ("synthesis/sixbar_path_case.yaml", ["synth", "mechanism"],
     lambda d: d["variables"][0].update(length="no"), "variables[0].length: must be true or false"),
])
def test_wrongly_typed_settings_are_one_line_naming_the_field(run_cli, tmp_path, source, args, change, words):
    f = _edited(tmp_path, ROOT / "examples" / source, change)
    msg = _exit2(run_cli, *args[:2], f, *args[2:], "--time-limit", "1")
    assert f.name in msg and words in msg, msg
