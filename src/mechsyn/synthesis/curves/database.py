"""A local database of coupler curves: random designs of every candidate topology.

For each topology (:func:`~mechsyn.synthesis.curves.topologies.curve_topologies`)
random designs are drawn (:func:`sample_designs`: frame pivots and floating joints in a
box, the crank's other joints close to its pivot so that many cranks turn fully, the
tracing point near its link's joints) and run through the batch engine
(:func:`mechsyn.kinematics.batch.simulate_batch`) over a full turn of the crank. A
design is kept when

* the crank turns fully without a dead point or a stepped-over dead point (a closed
  curve), or
* the crank oscillates over a clear range (at least :data:`MIN_RANGE` degrees) around
  the reference configuration, without a branch jump (an open arc);

and the tracing point's curve is not degenerate (it moves). Each kept design is
stored with its input range and the Fourier descriptor of its curve
(:mod:`~mechsyn.synthesis.curves.descriptors`), ``float32``, one ``.npz`` file per
topology in a directory (default ``$MECHSYN_CURVE_DB`` or
``~/.cache/mechsyn/curves-v2``). The default database holds 3,000 curves of each
four- and six-bar topology and 300 of each of the 279 eight-bar topologies (129,000
curves). Building is resumable: a topology whose file already
holds the requested number of curves is skipped, a short one is extended with new
random designs (the seed continues from the count already drawn).
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mechsyn.kinematics.batch import simulate_batch
from mechsyn.progress import ProgressCallback, report
from mechsyn.results import write_atomic
from mechsyn.synthesis.curves.descriptors import fourier_descriptor, resample
from mechsyn.synthesis.curves.topologies import TRACER, CurveTopology, cached_topologies, curve_topologies

__all__ = ["CurveDatabase", "build_database", "load_database", "default_database_dir", "sample_designs",
           "evaluate_designs", "DEFAULT_PER_TOPOLOGY", "MIN_RANGE"]

SWEEP_SAMPLES = 120          # 3 degree steps over a full turn
MIN_RANGE = 60.0             # degrees of crank oscillation for an open arc
DEFAULT_PER_TOPOLOGY = 3000   # curves per four- and six-bar topology
EIGHT_SHARE = 10               # an eight-bar topology holds per_topology / EIGHT_SHARE curves
DEFAULT_LINKS = 8              # the default database: 4-, 6- and 8-bars (1 + 14 + 279 topologies)
VERSION = 2                    # 2: eight-bars in the default database


def default_database_dir() -> Path:
    """``$MECHSYN_CURVE_DB`` or ``~/.cache/mechsyn/curves-v2``."""
    env = os.environ.get("MECHSYN_CURVE_DB")
    if env:
        return Path(env)
    base = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
    return base / "mechsyn" / f"curves-v{VERSION}"


def sample_designs(topo: CurveTopology, k: int, rng: np.random.Generator) -> np.ndarray:
    """``k`` random designs ``(k, P)`` of a topology (see the module doc)."""
    names = topo.plan.names
    links = topo.links_of()
    n = len(names)
    xy = rng.uniform(-1.0, 1.0, size=(k, n, 2))
    idx = {nm: i for i, nm in enumerate(names)}
    pivot = idx[topo.plan.input_joint]
    crank = links[f"L{topo.input}"]
    for nm in crank:
        if nm == topo.plan.input_joint:
            continue
        r = rng.uniform(0.1, 0.5, size=k)
        a = rng.uniform(0, 2 * np.pi, size=k)
        xy[:, idx[nm]] = xy[:, pivot] + np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
    on = [idx[nm] for nm in links[f"L{topo.tracer}"] if nm != TRACER]
    xy[:, idx[TRACER]] = xy[:, on].mean(axis=1) + rng.normal(scale=0.6, size=(k, 2))
    return xy.reshape(k, 2 * n)


@dataclass
class Evaluated:
    """Designs that passed (see :func:`evaluate_designs`)."""

    designs: np.ndarray     # (n, P)
    ranges: np.ndarray      # (n, 2) input offsets [start, stop] degrees
    closed: np.ndarray      # (n,) bool
    curves: np.ndarray      # (n, M) complex, arc-length resampled (open: there and back)
    descriptors: np.ndarray


def _runs_around_zero(ok: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per row of a cyclic mask (sample 0 = reference): assembled samples forward of 0
    and backward of 0 before the first unassembled one."""
    n = ok.shape[1]
    bad = ~ok
    fwd = np.where(bad.any(axis=1), np.argmax(bad, axis=1), n)
    back = np.where(bad.any(axis=1), np.argmax(bad[:, ::-1], axis=1), n)
    return fwd, back


def evaluate_designs(topo: CurveTopology, designs: np.ndarray, samples: int = SWEEP_SAMPLES) -> Evaluated:
    """Run designs over a full turn and keep the usable ones (see the module doc)."""
    step = 360.0 / samples
    off = np.arange(samples) * step
    res = simulate_batch(topo.plan, designs, off)
    P = res.paths[TRACER]
    ok = res.assembled
    closed = res.full_cycle
    fwd, back = _runs_around_zero(ok)
    span = (fwd + back - 1) * step
    arc = ~closed & ~res.branch_jump & ok[:, 0] & (span >= MIN_RANGE) & (fwd < samples)
    keep = closed | arc
    idx = np.flatnonzero(keep)
    curves = np.empty((len(idx), 64), complex)
    ranges = np.zeros((len(idx), 2))
    good = np.ones(len(idx), bool)
    z = P[..., 0] + 1j * P[..., 1]
    for r, i in enumerate(idx):
        if closed[i]:
            pts = z[i]
            ranges[r] = (0.0, 360.0)
            curves[r] = resample(pts, 64, closed=True)
        else:
            seq = np.concatenate([z[i, samples - back[i]:], z[i, :fwd[i]]])
            ranges[r] = (-back[i] * step, (fwd[i] - 1) * step)
            curves[r] = resample(seq, 64, closed=False)
        ext = np.ptp(curves[r].real) + np.ptp(curves[r].imag)
        scale = np.abs(designs[i]).max()
        good[r] = ext > 1e-3 * scale
    idx, curves, ranges = idx[good], curves[good], ranges[good]
    return Evaluated(designs[idx], ranges, closed[idx], curves, fourier_descriptor(curves))


@dataclass
class CurveDatabase:
    """Kept designs of all topologies, rows aligned."""

    topologies: tuple[CurveTopology, ...]
    topology: np.ndarray        # (n,) index into topologies
    designs: np.ndarray         # (n, Pmax) float32, row r's first 2 * points(topology) columns its design
    ranges: np.ndarray          # (n, 2) degrees (offsets from the reference)
    closed: np.ndarray          # (n,) bool
    descriptors: np.ndarray     # (n, D) float32

    def __len__(self) -> int:
        return len(self.topology)

    def design(self, row: int) -> np.ndarray:
        """Row ``row``'s design ``(P,)`` (float, in its topology's ``plan.names`` order)."""
        return np.asarray(self.designs[row, :_width(self.topologies[int(self.topology[row])])], float)

    def index(self, n_links: int):
        """``(DescriptorIndex, rows)`` over the descriptors of the ``n_links``-bar rows
        (built once per link count; ``(None, rows)`` when there are none)."""
        cache = self.__dict__.setdefault("_indexes", {})
        if n_links not in cache:
            from mechsyn.synthesis.curves.index import DescriptorIndex

            links = np.array([t.n_links for t in self.topologies])[self.topology]
            rows = np.flatnonzero(links == n_links)
            cache[n_links] = (DescriptorIndex(self.descriptors[rows]) if len(rows) else None, rows)
        return cache[n_links]


def _database_dir(directory: str | os.PathLike[str] | None) -> Path:
    """The database's directory (default :func:`default_database_dir`); a path that exists
    and is not a directory (a file, a device, a FIFO) is refused naming it."""
    path = Path(directory) if directory is not None else default_database_dir()
    if path.exists() and not path.is_dir():
        from mechsyn.errors import MechsynInputError

        raise MechsynInputError("the curve database is not a directory", source=str(path), field="database",
                                hint="give the directory of a curve database (or a new one to build)")
    return path


def _file(directory: Path, topo: CurveTopology) -> Path:
    return directory / f"{topo.key}.npz"


_KEYS = ("designs", "ranges", "closed", "descriptors", "drawn")


def _read(path: Path, topo: CurveTopology | None = None) -> dict | None:
    """A topology's file, or None when it is missing or damaged (see :func:`_read_checked`):
    it is then rebuilt."""
    try:
        return _read_checked(path, topo)
    except _Damaged:
        return None


class _Damaged(Exception):
    """What is wrong with a database file (its message)."""


#: member -> (dtype kinds, number of dimensions) of a topology's file
_LAYOUT = {"designs": ("f", 2), "ranges": ("f", 2), "closed": ("b", 1), "descriptors": ("f", 2), "drawn": ("iu", 0)}
_DEFLATE_RATIO = 1100  # deflate never expands more than 1032-fold: a larger declared size is forged


def _read_checked(path: Path, topo: CurveTopology | None = None) -> dict:
    """A topology's file, every member checked before it is loaded: a regular file, each
    ``.npy`` header's dtype and shape (rows alike, ``2 * N_HARMONICS`` descriptor columns,
    ``2 * joints`` design columns when ``topo`` is given) agreeing with the member's size
    in the archive (so a header declaring 1e11 rows is refused without allocating), then
    the values finite; :class:`_Damaged` saying what is wrong otherwise."""
    import stat
    import zipfile

    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            raise _Damaged("not a regular file")
        with zipfile.ZipFile(path) as zf:
            shapes = {k: _member_header(zf, k, info.st_size) for k in _KEYS}
            _check_shapes(shapes, topo)
            with np.load(path, allow_pickle=False) as f:
                data = {k: f[k] for k in _KEYS}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, MemoryError) as exc:
        raise _Damaged(f"not a readable .npz file ({type(exc).__name__})") from None
    for k in ("designs", "ranges", "descriptors"):
        if not np.isfinite(data[k]).all():
            raise _Damaged(f"{k} holds values that are not finite numbers")
    return data


def _member_header(zf, key: str, file_size: int) -> tuple:
    """``(dtype, shape)`` of member ``key.npy`` from its header, checked against the
    member's declared size (and that against its compressed size and the file's)."""
    member = zf.getinfo(f"{key}.npy")
    if member.compress_size > file_size or member.file_size > _DEFLATE_RATIO * member.compress_size + 4096:
        raise _Damaged(f"{key}: the archive declares {member.file_size:,} bytes")
    with zf.open(member) as fh:
        version = np.lib.format.read_magic(fh)
        read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
        shape, _, dtype = read(fh)
        header = fh.tell()
    kinds, ndim = _LAYOUT[key]
    if dtype.hasobject or (dtype.kind not in kinds and not (shape and shape[0] == 0)):
        raise _Damaged(f"{key}: dtype {dtype} (expected {'/'.join(kinds)})")
    if header + int(np.prod(shape, dtype=object)) * dtype.itemsize != member.file_size:
        raise _Damaged(f"{key}: the header's shape {shape} does not match the member's {member.file_size:,} bytes")
    return shape


def _check_shapes(shapes: dict, topo: CurveTopology | None) -> None:
    """The members' shapes agree: as many rows each, descriptor and design widths (an
    empty file holds 1-D empty arrays)."""
    from mechsyn.synthesis.curves.descriptors import N_HARMONICS

    n = shapes["ranges"][0] if shapes["ranges"] else -1
    if shapes["drawn"] != ():
        raise _Damaged(f"drawn: shape {shapes['drawn']}, expected a single number")
    if n == 0 and all(shapes[k] == (0,) for k in ("designs", "ranges", "closed", "descriptors")):
        return
    widths = {"ranges": 2, "descriptors": 2 * N_HARMONICS, "designs": None if topo is None else _width(topo)}
    for k in ("designs", "ranges", "closed", "descriptors"):
        kinds, ndim = _LAYOUT[k]
        if len(shapes[k]) != ndim or shapes[k][0] != n or (ndim == 2 and widths[k] not in (None, shapes[k][1])):
            want = (n, widths[k] or "P")[:ndim]
            raise _Damaged(f"{k}: shape {shapes[k]}, expected {want}".replace("'", ""))


def build_database(directory: str | os.PathLike[str] | None = None, max_links: int = DEFAULT_LINKS,
                   per_topology: int = DEFAULT_PER_TOPOLOGY, seed: int = 0, batch: int = 4000,
                   progress: ProgressCallback | None = None, scheduler: str | None = None) -> Path:
    """Build or extend the curve database (resumable; see the module doc): ``per_topology``
    curves of each four- and six-bar topology, a tenth of that (:data:`EIGHT_SHARE`) of
    each eight-bar one.

    ``progress(state)`` (:class:`mechsyn.progress.Progress`) is called after each topology
    with stage ``"build"``, topologies ``done`` of ``total`` and the curves kept so far in its
    ``message``. With ``scheduler`` (a
    ``dask.distributed`` address or ``Client``) the topologies are built on a Dask
    cluster and written here.
    """
    directory = _database_dir(directory)
    directory.mkdir(parents=True, exist_ok=True)
    topos = curve_topologies(max_links)
    todo = []
    for i, t in enumerate(topos):
        have = _read(_file(directory, t), t)
        n = 0 if have is None else len(have["ranges"])
        want = per_topology if t.n_links < 8 else max(1, per_topology // EIGHT_SHARE)
        if n < want:
            todo.append((i, t.key, max_links, want, seed, batch, have))
    total, done, kept = len(topos), len(topos) - len(todo), 0
    report(progress, done, total, "build", message=f"{kept} curves")
    if scheduler is not None and todo:
        client = _dask_client(scheduler)
        futures = client.map(_build_one, todo, pure=False)
        from dask.distributed import as_completed

        for fut in as_completed(futures):
            key, data = fut.result()
            _write(directory / f"{key}.npz", data)
            done += 1
            kept += len(data["ranges"])
            report(progress, done, total, "build", message=f"{kept} curves")
        return directory
    for job in todo:
        key, data = _build_one(job)
        _write(directory / f"{key}.npz", data)
        done += 1
        kept += len(data["ranges"])
        report(progress, done, total, "build", message=f"{kept} curves")
    return directory


def _dask_client(scheduler):
    """A ``dask.distributed`` client for an address (or the client given)."""
    from mechsyn.errors import MechsynInputError

    try:
        from dask.distributed import Client
    except ImportError:
        raise MechsynInputError("dask.distributed is not installed", field="scheduler",
                                hint="pip install 'mechsyn[dask]' or run without a scheduler") from None
    if isinstance(scheduler, Client):
        return scheduler
    try:
        return Client(scheduler, timeout=10)
    except (OSError, TimeoutError) as exc:
        raise MechsynInputError(f"cannot reach the Dask scheduler: {exc}", field="scheduler",
                                hint="give the address printed by dask-scheduler, e.g. tcp://host:8786") from None


def _write(path: Path, data: dict) -> None:
    buf = io.BytesIO()
    np.savez_compressed(buf, **data)
    write_atomic(path, buf.getvalue())


def _build_one(job) -> tuple[str, dict]:
    i, key, max_links, per_topology, seed, batch, have = job
    topo = next(t for t in curve_topologies(max_links) if t.key == key)
    drawn = 0 if have is None else int(have["drawn"])
    parts = {k: [have[k]] for k in ("designs", "ranges", "closed", "descriptors")} if have is not None else \
        {k: [] for k in ("designs", "ranges", "closed", "descriptors")}
    n = 0 if have is None else len(have["ranges"])
    tries = 0
    while n < per_topology and tries < 200:
        size = int(min(batch, 2 * (per_topology - n) + 64))
        rng = np.random.default_rng([seed, i, drawn])
        ev = evaluate_designs(topo, sample_designs(topo, size, rng))
        drawn += size
        tries += 1
        take = min(per_topology - n, len(ev.ranges))
        parts["designs"].append(ev.designs[:take].astype(np.float32))
        parts["ranges"].append(ev.ranges[:take].astype(np.float32))
        parts["closed"].append(ev.closed[:take])
        parts["descriptors"].append(ev.descriptors[:take].astype(np.float32))
        n += take
    data = {k: np.concatenate(v) if v else np.zeros(0) for k, v in parts.items()}
    data["drawn"] = np.array(drawn)
    return key, data


def load_database(directory: str | os.PathLike[str] | None = None, max_links: int = 8,
                  build_if_missing: bool = True, progress: ProgressCallback | None = None) -> CurveDatabase:
    """Read the database (topologies up to ``max_links``); build the default one first when
    there is none.

    The topologies' files are read and checked once and packed into one memory-mapped
    set of arrays (``packed/`` in the directory, keyed by the files' names, sizes and
    modification times): later loads map it in milliseconds instead of decompressing and
    checking every file again (a second or more, several under load).
    """
    directory = _database_dir(directory)
    topos = cached_topologies(directory, max(max_links, 4)) if directory.is_dir() else curve_topologies(max(max_links, 4))
    present = [t for t in topos if _file(directory, t).exists()]
    if not present and build_if_missing:
        build_database(directory, max_links=min(max_links, DEFAULT_LINKS), per_topology=DEFAULT_PER_TOPOLOGY,
                       progress=progress)
        present = [t for t in topos if _file(directory, t).exists()]
    stamp = _stamp(directory, present)
    packed = _read_packed(directory, present, stamp)
    if packed is not None:
        return packed
    db = _read_files(directory, present)
    _write_packed(directory, db, stamp)
    return db


def _read_files(directory: Path, present: list[CurveTopology]) -> CurveDatabase:
    """The database from the topologies' files, each checked (:func:`_read_checked`)."""
    rows_t, designs, ranges, closed, desc = [], [], [], [], []
    for ti, t in enumerate(present):
        try:
            data = _read_checked(_file(directory, t), t)
        except _Damaged as exc:
            from mechsyn.errors import MechsynInputError

            raise MechsynInputError(f"the curve database file is damaged: {exc}", source=str(_file(directory, t)),
                                    hint=f"rebuild it: mechsyn curves build --links {t.n_links} "
                                         f"--database {directory} (with the --per-topology it was built with)") from None
        if len(data["ranges"]) == 0:
            continue
        m = len(data["ranges"])
        rows_t.append(np.full(m, ti))
        designs.append(np.asarray(data["designs"], np.float32))
        ranges.append(data["ranges"])
        closed.append(data["closed"])
        desc.append(data["descriptors"])
    if not rows_t:
        from mechsyn.errors import MechsynInputError

        raise MechsynInputError(f"no curve database in {directory}", field="database",
                                hint="run `mechsyn curves build`")
    width = max(d.shape[1] for d in designs)
    padded = np.concatenate([np.pad(d, ((0, 0), (0, width - d.shape[1]))) for d in designs])
    return CurveDatabase(tuple(present), np.concatenate(rows_t), padded, np.concatenate(ranges).astype(float),
                         np.concatenate(closed).astype(bool), np.concatenate(desc).astype(np.float32))


def _width(topo: CurveTopology) -> int:
    """Design columns of a topology: its joints and the tracer, x and y each (read from the
    template, without compiling the plan)."""
    return 2 * (len(topo.template["joints"]) + 1)


PACKED = "packed"      # the packed arrays' folder inside the database directory
_PACKED_KEYS = ("topology", "designs", "ranges", "closed", "descriptors")
_PACKED_KINDS = {"topology": "iu", "designs": "f", "ranges": "f", "closed": "b", "descriptors": "f"}


def _stamp(directory: Path, present: list[CurveTopology]) -> list:
    """What the packed arrays depend on: each topology file's key, size and modification time."""
    out = []
    for t in present:
        st = os.stat(_file(directory, t))
        out.append([t.key, st.st_size, st.st_mtime_ns])
    return out


def _read_packed(directory: Path, present: list[CurveTopology], stamp: list) -> CurveDatabase | None:
    """The packed arrays, memory-mapped, when their manifest matches ``stamp`` and they are
    whole (shapes, kinds, finite values, topology indices in range); None otherwise (they
    are then packed again from the files)."""
    import json

    from mechsyn.errors import MechsynInputError
    from mechsyn.io.files import read_limited

    folder = directory / PACKED
    try:
        manifest = json.loads(read_limited(folder / "manifest.json", "curve database manifest", cap=1 << 24))
        if manifest.get("version") != VERSION or manifest.get("sources") != stamp:
            return None
        a = {k: np.load(folder / f"{k}.npy", mmap_mode="r", allow_pickle=False) for k in _PACKED_KEYS}
    except (OSError, ValueError, TypeError, AttributeError, MechsynInputError):
        return None
    n = len(a["topology"])
    shapes_ok = all(a[k].dtype.kind in _PACKED_KINDS[k] and len(a[k]) == n for k in _PACKED_KEYS) and n > 0
    if not shapes_ok or a["designs"].ndim != 2 or a["ranges"].shape[1:] != (2,) or a["descriptors"].ndim != 2:
        return None
    top = a["topology"]
    if top.min() < 0 or top.max() >= len(present) or a["designs"].shape[1] < max(_width(t) for t in present):
        return None
    if not all(np.isfinite(a[k]).all() for k in ("designs", "ranges", "descriptors")):
        return None
    return CurveDatabase(tuple(present), np.asarray(top, np.intp), a["designs"], np.asarray(a["ranges"], float),
                         np.asarray(a["closed"], bool), a["descriptors"])


def _write_packed(directory: Path, db: CurveDatabase, stamp: list) -> None:
    """Pack the database's arrays for :func:`_read_packed` (the manifest last; a read-only
    directory is left as it is)."""
    import json

    folder = directory / PACKED
    arrays = {"topology": db.topology.astype(np.int32), "designs": db.designs, "ranges": db.ranges.astype(np.float32),
              "closed": db.closed, "descriptors": db.descriptors}
    try:
        (folder / "manifest.json").unlink(missing_ok=True)
        for k, v in arrays.items():
            buf = io.BytesIO()
            np.save(buf, np.ascontiguousarray(v), allow_pickle=False)
            write_atomic(folder / f"{k}.npy", buf.getvalue())
        write_atomic(folder / "manifest.json", json.dumps({"version": VERSION, "sources": stamp}))
    except OSError:
        pass
