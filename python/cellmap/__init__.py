"""cellmap: basins of attraction by cell mapping, from Python.

A thin ctypes layer over libcellmap (cellmap/cellmap.h); no compiler is
needed. Arrays come back as numpy int32 arrays shaped like the lattice, as
`cellmap export --labels/--steps` writes them: for cells (nx, ny),
labels[i, j] is the cell i along the first coordinate and j along the
second; a label is 0 for the sink, k for group k, -1 for a cell that no
region of a database computed. attractor_labels are the system's
attractors behind the groups (found by their true orbits, as `cellmap
solve` does, sink cells by the true orbits from where their sequences
leave the cells): k for attractor k, 0 diverged, -2 outside (left the
cells and did not come back, or its group's orbit was undecided), -1 not
computed, as `cellmap export --labels` writes them.

    import cellmap
    pd = cellmap.System("microchaos-pd", alpha=0.078, beta=0, P=0.007, D=0.02)
    res = cellmap.solve(pd, region=[(0, 500), (-40, 40)], cells=(800, 400))
    print(res.groups[0], (res.labels == 0).mean())   # a group; the sink's share
    print(res.attractors[0], (res.attractor_labels == 1).mean())
    view = cellmap.open("file.cmdb").read(view=[(100, 200), (-10, 10)])

The library is found next to an installed cellmap (PREFIX/lib, for a
module pip installed under the same PREFIX), then where pkg-config says
cellmap is, then on the system's library path; $CELLMAP_LIB overrides.

Beyond solving and reading (the stable part of libcellmap), the module
drives the workstation through libcellmap's experimental section:
databases made, resumed and grown (create, resume, add_box, extend),
their arrays exported
(export), explore sessions (Session: view, pan, zoom, extend, read,
figure), figures with every option (Result.figure), and systems given as a
Python function (System.from_function).
"""
import ctypes
import ctypes.util
import json
import os
import subprocess
import sysconfig

import numpy as np

__all__ = ["System", "Models", "Result", "Database", "Session", "solve", "open", "create",
           "resume", "add_box", "extend", "export", "models", "CellmapError", "LABEL_NONE", "version", "analysis"]

LABEL_NONE = -1
_MAX_DIM = 6
_MSG = 1024


class CellmapError(RuntimeError):
    """A libcellmap call failed: .status is its code, the text says why."""

    def __init__(self, status, message):
        super().__init__(message)
        self.status = status


def _candidates():
    env = os.environ.get("CELLMAP_LIB")
    if env:
        yield env
    # installed beside cellmap: PREFIX/lib/libcellmap.so.0, whatever the
    # site scheme put the package under PREFIX (lib/pythonX.Y/site-packages,
    # Debian's local/lib/pythonX.Y/dist-packages, a --target directory)
    here = os.path.dirname(os.path.abspath(__file__))
    up = here
    for _ in range(7):
        up = os.path.dirname(up)
        for sub in ("lib", "lib64", os.path.join("lib", _multiarch())):
            path = os.path.join(up, sub, "libcellmap.so.0")
            if os.path.exists(path):
                yield path
    # where pkg-config says cellmap is (its default path covers /usr/local)
    try:
        libdir = subprocess.run(["pkg-config", "--variable=libdir", "cellmap"],
                                capture_output=True, text=True, timeout=10).stdout.strip()
        if libdir:
            yield os.path.join(libdir, "libcellmap.so.0")
    except (OSError, subprocess.SubprocessError):
        pass
    found = ctypes.util.find_library("cellmap")
    if found:
        yield found
    yield "libcellmap.so.0"


def _multiarch():
    try:
        return sysconfig.get_config_var("MULTIARCH") or ""
    except Exception:  # noqa: BLE001 - a missing variable is no reason to fail the import
        return ""


def _load():
    errors = []
    for path in _candidates():
        try:
            return ctypes.CDLL(path)
        except OSError as e:
            errors.append(str(e))
    raise ImportError("libcellmap not found (install cellmap, or set CELLMAP_LIB to "
                      "libcellmap.so): " + "; ".join(errors))


class _Grid(ctypes.Structure):
    _fields_ = [("dim", ctypes.c_int), ("lo", ctypes.c_double * _MAX_DIM),
                ("hi", ctypes.c_double * _MAX_DIM), ("cells", ctypes.c_int64 * _MAX_DIM)]


_PROGRESS = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double)


class _Options(ctypes.Structure):
    _fields_ = [("threads", ctypes.c_int), ("max_steps", ctypes.c_int),
                ("split", ctypes.c_int64 * _MAX_DIM), ("progress", _PROGRESS),
                ("user", ctypes.c_void_p)]


class _Group(ctypes.Structure):
    _fields_ = [("id", ctypes.c_uint32), ("kind", ctypes.c_int), ("period", ctypes.c_uint32),
                ("basin_cells", ctypes.c_uint64), ("centre", ctypes.c_double * _MAX_DIM)]


class _Attractor(ctypes.Structure):
    _fields_ = [("id", ctypes.c_uint32), ("kind", ctypes.c_int), ("period", ctypes.c_uint32),
                ("basin_cells", ctypes.c_uint64), ("groups", ctypes.c_uint32),
                ("centre", ctypes.c_double * _MAX_DIM), ("lo", ctypes.c_double * _MAX_DIM),
                ("hi", ctypes.c_double * _MAX_DIM), ("anchor", ctypes.c_int64 * _MAX_DIM),
                ("footprint_cells", ctypes.c_uint64)]


_lib = _load()
_P = ctypes.c_void_p


def _sig(name, res, *args):
    f = getattr(_lib, name)
    f.restype, f.argtypes = res, list(args)


_sig("cm_version", ctypes.c_char_p)
_sig("cm_models_new", ctypes.c_int, ctypes.POINTER(_P), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_models_load", ctypes.c_int, _P, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_models_count", ctypes.c_size_t, _P)
_sig("cm_models_name", ctypes.c_char_p, _P, ctypes.c_size_t)
_sig("cm_models_free", None, _P)
_sig("cm_system_new", ctypes.c_int, _P, ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(_P),
     ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_system_dim", ctypes.c_int, _P)
_sig("cm_system_name", ctypes.c_char_p, _P)
_sig("cm_system_coord", ctypes.c_char_p, _P, ctypes.c_int)
_sig("cm_system_region", ctypes.c_int, _P, ctypes.POINTER(ctypes.c_double),
     ctypes.POINTER(ctypes.c_double))
_sig("cm_system_step", ctypes.c_int, _P, ctypes.POINTER(ctypes.c_double),
     ctypes.POINTER(ctypes.c_double))
_sig("cm_system_free", None, _P)
_sig("cm_solve", ctypes.c_int, _P, ctypes.POINTER(_Grid), ctypes.POINTER(_Options),
     ctypes.POINTER(_P), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_result_grid", None, _P, ctypes.POINTER(_Grid))
_sig("cm_result_cells", ctypes.c_uint64, _P)
_sig("cm_result_labels", None, _P, ctypes.POINTER(ctypes.c_uint32))
_sig("cm_result_steps", None, _P, ctypes.POINTER(ctypes.c_uint32))
_sig("cm_result_groups", ctypes.c_uint32, _P)
_sig("cm_result_group", ctypes.c_int, _P, ctypes.c_uint32, ctypes.POINTER(_Group))
_sig("cm_result_attractors", ctypes.c_uint32, _P)
_sig("cm_result_attractor", ctypes.c_int, _P, ctypes.c_uint32, ctypes.POINTER(_Attractor))
_sig("cm_result_attractor_labels", None, _P, ctypes.POINTER(ctypes.c_int32))
_sig("cm_result_png", ctypes.c_int, _P, ctypes.c_char_p, ctypes.c_int, ctypes.c_int,
     ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_result_free", None, _P)
_sig("cm_db_open", ctypes.c_int, ctypes.c_char_p, ctypes.POINTER(_P), ctypes.c_char_p,
     ctypes.c_size_t)
_sig("cm_db_model", ctypes.c_char_p, _P)
_sig("cm_db_params", ctypes.c_char_p, _P)
_sig("cm_db_grid", None, _P, ctypes.POINTER(_Grid))
_sig("cm_db_read", ctypes.c_int, _P, ctypes.POINTER(ctypes.c_double),
     ctypes.POINTER(ctypes.c_double), ctypes.POINTER(_P), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_db_close", None, _P)


def version():
    """libcellmap's version, "MAJOR.MINOR.PATCH"."""
    return _lib.cm_version().decode()


def _call(fn, *args):
    msg = ctypes.create_string_buffer(_MSG)
    st = fn(*args, msg, _MSG)
    if st != 0:
        raise CellmapError(st, msg.value.decode(errors="replace") or "status %d" % st)


def _text(value):
    return None if value is None else str(value).encode()


class Models:
    """cellmap's models plus those of plugins (shared objects, see examples/plugin)."""

    def __init__(self, plugins=()):
        self._h = _P()
        _call(_lib.cm_models_new, ctypes.byref(self._h))
        for path in plugins:
            _call(_lib.cm_models_load, self._h, _text(os.fspath(path)))

    def names(self):
        return [_lib.cm_models_name(self._h, i).decode()
                for i in range(_lib.cm_models_count(self._h))]

    def __del__(self):
        if getattr(self, "_h", None):
            _lib.cm_models_free(self._h)
            self._h = None


def models():
    """The names of cellmap's own models."""
    return Models().names()


def _params_text(params, kw):
    parts = [params] if params else []
    parts += ["%s=%s" % (k, ":".join(repr(float(x)) for x in v) if isinstance(v, (list, tuple))
                         else v if isinstance(v, str) else repr(float(v)))
              for k, v in kw.items()]
    return ",".join(parts)


class System:
    """A model built with its parameters: System("duffing", gamma=0.3), or
    System("henon", plugins=["./libhenon.so"], a=1.4)."""

    def __init__(self, name, params=None, plugins=(), **kw):
        self.models = Models(plugins) if plugins else None
        self._h = _P()
        _call(_lib.cm_system_new, self.models._h if self.models else None, _text(name),
              _text(_params_text(params, kw)), ctypes.byref(self._h))
        self.name = _lib.cm_system_name(self._h).decode()
        self.dim = _lib.cm_system_dim(self._h)
        self.coords = [_lib.cm_system_coord(self._h, d).decode() for d in range(self.dim)]

    @classmethod
    def from_function(cls, name, dim, f):
        """A system whose map is the Python function f(x) -> y (x, y lists
        of dim floats; y None: no image, the sink). Called through ctypes
        once per image, from libcellmap's threads under the interpreter's
        lock (more threads do not make it faster): about 4-7 microseconds a
        cell for the Henon map, 13-17 times the same map as a compiled
        plugin (tests/bench_function_model.py measures both), so a map
        worth more than a quick look is worth a plugin (examples/plugin).
        An exception in f stops the solve and is raised from it."""
        self = cls.__new__(cls)
        self.models = None
        self._error = None

        def step(user, x, y):
            try:
                image = f([x[d] for d in range(dim)])
                if image is None:
                    return 1
                for d in range(dim):
                    y[d] = image[d]
                return 0
            except BaseException as e:  # noqa: BLE001 - raised again after the call
                self._error = self._error or e
                return -1

        self._step = _STEP(step)  # kept alive as long as the system
        self._h = _P()
        _call(_lib.cm_system_from_function, _text(name), int(dim), self._step, None,
              ctypes.byref(self._h))
        self.name = _lib.cm_system_name(self._h).decode()
        self.dim = _lib.cm_system_dim(self._h)
        self.coords = [_lib.cm_system_coord(self._h, d).decode() for d in range(self.dim)]
        return self

    def region(self):
        """The model's default region [(lo, hi), ...], or None."""
        lo, hi = (ctypes.c_double * self.dim)(), (ctypes.c_double * self.dim)()
        if _lib.cm_system_region(self._h, lo, hi) != 0:
            return None
        return list(zip(lo, hi))

    def step(self, x):
        """The image of state x (dim numbers), or None (the sink)."""
        x = [float(v) for v in x]
        if len(x) != self.dim:
            raise ValueError("model %s has dimension %d: step() needs %d numbers, not %d"
                             % (self.name, self.dim, self.dim, len(x)))
        xs = (ctypes.c_double * self.dim)(*x)
        ys = (ctypes.c_double * self.dim)()
        return list(ys) if _lib.cm_system_step(self._h, xs, ys) == 0 else None

    def __del__(self):
        if getattr(self, "_h", None):
            _lib.cm_system_free(self._h)
            self._h = None


class Result:
    """Labels, step numbers and groups of a grid of cells.

    labels: numpy int32 array shaped like the lattice (see the module's
    help): 0 the sink, 1.. a group, LABEL_NONE (-1) a cell no region covers.
    steps: steps to the group's periodic cells. groups: list of dicts (id,
    kind, period, basin_cells, centre). attractor_labels: the same array by
    the system's attractors (k attractor k, 0 diverged, -2 outside, -1 not
    computed); attractors: list of dicts (id, kind periodic|aperiodic|
    sticking, period (None when aperiodic), basin_cells, groups, centre,
    lo, hi, anchor, footprint_cells). lo, hi, cells: the grid."""

    def __init__(self, handle, owner):
        self._h, self._owner = handle, owner  # owner: the system or database it needs
        g = _Grid()
        _lib.cm_result_grid(handle, ctypes.byref(g))
        self.dim = g.dim
        self.lo = [g.lo[d] for d in range(g.dim)]
        self.hi = [g.hi[d] for d in range(g.dim)]
        self.cells = [int(g.cells[d]) for d in range(g.dim)]
        n = _lib.cm_result_cells(handle)
        self.labels = self._array(_lib.cm_result_labels, n)
        self.steps = self._array(_lib.cm_result_steps, n)
        self.groups = []
        for gid in range(1, _lib.cm_result_groups(handle) + 1):
            s = _Group()
            _lib.cm_result_group(handle, gid, ctypes.byref(s))
            self.groups.append({"id": s.id, "kind": "sticking" if s.kind else "attractor",
                                "period": s.period, "basin_cells": s.basin_cells,
                                "centre": [s.centre[d] for d in range(g.dim)]})
        self.attractor_labels = self._array(_lib.cm_result_attractor_labels, n,
                                            ctypes.c_int32, np.int32)
        self.attractors = []
        for aid in range(1, _lib.cm_result_attractors(handle) + 1):
            a = _Attractor()
            _lib.cm_result_attractor(handle, aid, ctypes.byref(a))
            kind = ("periodic", "aperiodic", "sticking")[a.kind]
            self.attractors.append({
                "id": a.id, "kind": kind, "period": None if a.kind == 1 else a.period,
                "basin_cells": a.basin_cells, "groups": a.groups,
                "centre": [a.centre[d] for d in range(g.dim)],
                "lo": [a.lo[d] for d in range(g.dim)], "hi": [a.hi[d] for d in range(g.dim)],
                "anchor": [a.anchor[d] for d in range(g.dim)],
                "footprint_cells": a.footprint_cells})

    def _array(self, fill, n, ctype=ctypes.c_uint32, dtype=np.uint32):
        """What fill writes (dimension 0 fastest), indexed [i0, i1, ...]."""
        flat = np.empty(n, dtype=dtype)
        fill(self._h, flat.ctypes.data_as(ctypes.POINTER(ctype)))
        return np.ascontiguousarray(flat.view(np.int32).reshape(tuple(reversed(self.cells))).T)

    def png(self, path, width=0, height=0):
        """Writes the basin figure, as `cellmap solve --png` draws it."""
        _call(_lib.cm_result_png, self._h, _text(os.fspath(path)), width, height)

    def figure(self, png=None, **options):
        """Writes the figure with render's options: png=PATH, svg=PATH
        and/or pdf=PATH, width, height, layers (names: basin, steps, attractors,
        overlays, axes, legend, title; default all but steps), indexed,
        by ("attractors" or "groups"), palette, labels (a file),
        min_basin, legend, title, aspect ("equal", "auto" or a ratio),
        font_size (points), dpi."""
        o, keep = _figure_options(png, options)
        _call(_lib.cm_result_figure, self._h, ctypes.byref(o))

    def __del__(self):
        if getattr(self, "_h", None):
            _lib.cm_result_free(self._h)
            self._h = None


def _grid(dim, region, cells):
    if len(region) != dim or len(cells) != dim:
        raise ValueError("region and cells need %d entries each" % dim)
    g = _Grid()
    g.dim = dim
    for d, ((lo, hi), n) in enumerate(zip(region, cells)):
        g.lo[d], g.hi[d], g.cells[d] = float(lo), float(hi), int(n)
    return g


def solve(system, region=None, cells=None, threads=0, max_steps=0, split=None, progress=None):
    """Simple cell mapping of region [(lo, hi), ...] (default: the model's) in
    cells (n0, n1, ...) cells (default 200 a side); split=(k0, k1, ...) solves
    that many regions concurrently and joins them (clustered SCM). progress,
    if given, is called with the fraction done; returning True cancels."""
    region = region or system.region()
    if region is None:
        raise ValueError("model %s has no default region: give region=" % system.name)
    cells = cells or [200] * system.dim
    g = _grid(system.dim, region, cells)
    opt = _Options()
    opt.threads, opt.max_steps = threads, max_steps
    for d, k in enumerate(split or ()):
        opt.split[d] = int(k)
    callback = _PROGRESS(lambda user, fraction: 1 if progress(fraction) else 0) \
        if progress else _PROGRESS()
    opt.progress = callback
    h = _P()
    try:
        _call(_lib.cm_solve, system._h, ctypes.byref(g), ctypes.byref(opt), ctypes.byref(h))
    except CellmapError as e:
        raised, system._error = getattr(system, "_error", None), None
        if raised is not None:
            raise raised from e
        raise
    return Result(h, system)


class Database:
    """A cluster database (.cmdb) that `cellmap solve --db` or `explore` wrote,
    opened read-only."""

    def __init__(self, path):
        self._h = _P()
        _call(_lib.cm_db_open, _text(os.fspath(path)), ctypes.byref(self._h))
        self.model = _lib.cm_db_model(self._h).decode()
        self.params = json.loads(_lib.cm_db_params(self._h).decode())
        g = _Grid()
        _lib.cm_db_grid(self._h, ctypes.byref(g))
        self.lo = [g.lo[d] for d in range(g.dim)]
        self.hi = [g.hi[d] for d in range(g.dim)]
        self.cells = [int(g.cells[d]) for d in range(g.dim)]

    def read(self, view=None):
        """The cells that meet view [(lo, hi), ...] (default: the whole cluster)."""
        h = _P()
        if view is None:
            _call(_lib.cm_db_read, self._h, None, None, ctypes.byref(h))
        else:
            view = list(view)
            if len(view) != len(self.lo):
                raise ValueError("the database has dimension %d: read() needs %d (lo, hi) "
                                 "ranges, not %d" % (len(self.lo), len(self.lo), len(view)))
            if any(len(r) != 2 for r in view):
                raise ValueError("read(): each range of the view is (lo, hi)")
            lo = (ctypes.c_double * len(view))(*[float(a) for a, _ in view])
            hi = (ctypes.c_double * len(view))(*[float(b) for _, b in view])
            _call(_lib.cm_db_read, self._h, lo, hi, ctypes.byref(h))
        return Result(h, self)

    def __del__(self):
        if getattr(self, "_h", None):
            _lib.cm_db_close(self._h)
            self._h = None


def open(path):  # noqa: A001 - cellmap.open(...) reads like the file it opens
    """Opens a .cmdb file read-only (see Database)."""
    return Database(path)


# ---- the experimental section of libcellmap ---------------------------------

_STEP = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(ctypes.c_double),
                         ctypes.POINTER(ctypes.c_double))


class _FigureOptions(ctypes.Structure):
    _fields_ = [("png", ctypes.c_char_p), ("svg", ctypes.c_char_p), ("width", ctypes.c_int),
                ("height", ctypes.c_int), ("layers", ctypes.c_uint), ("indexed", ctypes.c_int),
                ("by_groups", ctypes.c_int), ("palette", ctypes.c_char_p),
                ("labels", ctypes.c_char_p), ("min_basin", ctypes.c_uint64),
                ("legend", ctypes.c_int), ("title", ctypes.c_char_p),
                ("aspect", ctypes.c_double), ("font_size", ctypes.c_double),
                ("dpi", ctypes.c_double), ("pdf", ctypes.c_char_p)]


class _DbOptions(ctypes.Structure):
    _fields_ = [("threads", ctypes.c_int), ("max_steps", ctypes.c_int),
                ("split", ctypes.c_int64 * _MAX_DIM), ("extend", ctypes.c_int),
                ("escape_below", ctypes.c_double), ("mem", ctypes.c_uint64),
                ("command", ctypes.c_char_p), ("progress", _PROGRESS), ("user", ctypes.c_void_p),
                ("ranks", ctypes.c_void_p)]


class _SessionOptions(ctypes.Structure):
    _fields_ = [("model", ctypes.c_char_p), ("params", ctypes.c_char_p), ("set", ctypes.c_void_p),
                ("cell_size", ctypes.c_double * _MAX_DIM), ("origin", ctypes.c_double * _MAX_DIM),
                ("depth", ctypes.c_char_p), ("max_steps", ctypes.c_int), ("threads", ctypes.c_int),
                ("mem", ctypes.c_uint64), ("command", ctypes.c_char_p)]


class _CellInfo(ctypes.Structure):
    _fields_ = [("cell", ctypes.c_int64 * _MAX_DIM), ("centre", ctypes.c_double * _MAX_DIM),
                ("label", ctypes.c_uint32), ("step", ctypes.c_uint32),
                ("attractor", ctypes.c_int32)]


_DOUBLES = ctypes.POINTER(ctypes.c_double)
_sig("cm_system_from_function", ctypes.c_int, ctypes.c_char_p, ctypes.c_int, _STEP, _P,
     ctypes.POINTER(_P), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_result_figure", ctypes.c_int, _P, ctypes.POINTER(_FigureOptions), ctypes.c_char_p,
     ctypes.c_size_t)
_sig("cm_ranks_open", ctypes.c_int, ctypes.POINTER(_P), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_ranks_rank", ctypes.c_int, _P)
_sig("cm_ranks_size", ctypes.c_int, _P)
_sig("cm_ranks_close", None, _P)
for _name in ("cm_db_create", "cm_db_resume"):
    _sig(_name, ctypes.c_int, _P, ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(_Grid),
         ctypes.c_char_p, ctypes.POINTER(_DbOptions), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_db_add_box", ctypes.c_int, ctypes.c_char_p, _DOUBLES, _DOUBLES,
     ctypes.POINTER(_DbOptions), ctypes.POINTER(ctypes.c_uint64), ctypes.c_char_p,
     ctypes.c_size_t)
_sig("cm_db_extend", ctypes.c_int, ctypes.c_char_p, _DOUBLES, _DOUBLES, ctypes.c_int,
     ctypes.POINTER(_DbOptions), ctypes.POINTER(ctypes.c_int), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_db_export", ctypes.c_int, ctypes.c_char_p, _DOUBLES, _DOUBLES, ctypes.c_char_p,
     ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_session_open", ctypes.c_int, ctypes.c_char_p, ctypes.POINTER(_SessionOptions),
     ctypes.POINTER(_P), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_session_view", ctypes.c_int, _P, _DOUBLES, _DOUBLES, ctypes.POINTER(ctypes.c_uint64),
     ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_session_bounds", ctypes.c_int, _P, _DOUBLES, _DOUBLES)
_sig("cm_session_pan", ctypes.c_int, _P, ctypes.c_int, ctypes.c_double,
     ctypes.POINTER(ctypes.c_uint64), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_session_zoom", ctypes.c_int, _P, ctypes.c_double, ctypes.POINTER(ctypes.c_uint64),
     ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_session_extend", ctypes.c_int, _P, ctypes.c_int, ctypes.POINTER(ctypes.c_int),
     ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_session_read", ctypes.c_int, _P, ctypes.POINTER(_P), ctypes.c_char_p, ctypes.c_size_t)
_sig("cm_session_query", ctypes.c_int, _P, _DOUBLES, ctypes.POINTER(_CellInfo), ctypes.c_char_p,
     ctypes.c_size_t)
_sig("cm_session_figure", ctypes.c_int, _P, ctypes.POINTER(_FigureOptions), ctypes.c_char_p,
     ctypes.c_size_t)
_sig("cm_session_close", ctypes.c_int, _P, ctypes.c_char_p, ctypes.c_size_t)

_LAYERS = {"basin": 1, "steps": 2, "attractors": 4, "overlays": 8, "axes": 16, "legend": 32,
           "title": 64}
_FIGURE_KEYS = {"svg", "pdf", "width", "height", "layers", "indexed", "by", "palette", "labels",
                "min_basin", "legend", "title", "aspect", "font_size", "dpi"}


def _figure_options(png, options):
    """The C options of a figure, and the encoded texts they point to."""
    unknown = set(options) - _FIGURE_KEYS
    if unknown:
        raise TypeError("figure(): unknown option(s) %s; known: png, %s"
                        % (", ".join(sorted(unknown)), ", ".join(sorted(_FIGURE_KEYS))))
    layers = options.get("layers")
    bits = 0
    for name in ([layers] if isinstance(layers, str) else layers or ()):
        if name not in _LAYERS:
            raise ValueError("figure(): layer %r; known: %s" % (name, ", ".join(_LAYERS)))
        bits |= _LAYERS[name]
    by = options.get("by", "attractors")
    if by not in ("attractors", "groups"):
        raise ValueError("figure(): by=%r: 'attractors' or 'groups'" % (by,))
    keep = [_text(os.fspath(v)) if v is not None else None
            for v in (png, options.get("svg"), options.get("palette"), options.get("labels"))]
    keep.append(_text(options["title"]) if options.get("title") is not None else None)
    keep.append(_text(os.fspath(options["pdf"])) if options.get("pdf") is not None else None)
    aspect = options.get("aspect", 0)
    aspect = {"equal": 1.0, "auto": -1.0}.get(aspect, aspect)
    if isinstance(aspect, str):
        raise ValueError("figure(): aspect=%r: 'equal', 'auto' or a ratio" % (aspect,))
    o = _FigureOptions(keep[0], keep[1], int(options.get("width", 0)),
                       int(options.get("height", 0)), bits, int(bool(options.get("indexed"))),
                       int(by == "groups"), keep[2], keep[3], int(options.get("min_basin", 0)),
                       int(options.get("legend", 0)), keep[4], float(aspect),
                       float(options.get("font_size", 0)), float(options.get("dpi", 0)),
                       keep[5])
    return o, keep


class Ranks:
    """The processes mpirun started, for solves shared among them:
    create(..., ranks=r) and resume(..., ranks=r) on every rank, with the
    same arguments; rank 0 solves and writes the file, the others solve
    regions for it and get None back. Outside mpirun: one rank, and MPI is
    not loaded. Under mpirun libcellmap loads libcellmap-mpi.so.0 (built
    where MPI is found) and starts MPI, unless the program started it
    (mpi4py, at MPI_THREAD_SERIALIZED or above). One per process; close()
    (or `with`) ends them."""

    def __init__(self):
        h = _P()
        _call(_lib.cm_ranks_open, ctypes.byref(h))
        self._h = h

    @property
    def rank(self):
        return _lib.cm_ranks_rank(self._h)

    @property
    def size(self):
        return _lib.cm_ranks_size(self._h)

    def close(self):
        if getattr(self, "_h", None):
            _lib.cm_ranks_close(self._h)
            self._h = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()


def _db_call(fn, path, model, params, plugins, region, cells, split, extend, escape_below,
             threads, max_steps, mem, command, progress, kw, ranks=None):
    models = Models(plugins) if plugins else None
    dim = len(region)
    g = _grid(dim, region, cells)
    o = _DbOptions()
    o.threads, o.max_steps, o.extend, o.escape_below, o.mem = (
        threads, max_steps, extend, float(escape_below), mem)
    for d, k in enumerate(split or ()):
        o.split[d] = int(k)
    o.command = _text(command)
    callback = _PROGRESS(lambda user, fraction: 1 if progress(fraction) else 0) \
        if progress else _PROGRESS()
    o.progress = callback
    o.ranks = ranks._h if ranks is not None else None
    _call(fn, models._h if models else None, _text(model), _text(_params_text(params, kw)),
          ctypes.byref(g), _text(os.fspath(path)), ctypes.byref(o))
    return ranks is None or ranks.rank == 0


def create(path, model, region, cells, params=None, plugins=(), split=None, extend=0,
           escape_below=0.0, threads=0, max_steps=0, mem=0, command=None, progress=None,
           ranks=None, **kw):
    """Solves region [(lo, hi), ...] in cells (n0, n1, ...) of `model` into a
    new database at path, as `cellmap solve --db PATH` with --split, --extend,
    --escape-below, --max-steps, --threads and --mem; the system's attractors
    are stored with it. Parameter values as keywords (alpha=0.078) or
    params="k=v,...". progress(fraction) returning True cancels: the joins
    done are kept, and resume() completes the file. ranks (a Ranks): the
    regions shared among MPI ranks; None on ranks other than 0."""
    if _db_call(_lib.cm_db_create, path, model, params, plugins, region, cells, split, extend,
                escape_below, threads, max_steps, mem, command, progress, kw, ranks):
        return Database(path)
    return None


def resume(path, model, region, cells, params=None, plugins=(), split=None, extend=0,
           escape_below=0.0, threads=0, max_steps=0, mem=0, command=None, progress=None,
           ranks=None, **kw):
    """Completes a database create() (or `cellmap solve --db`) began, given
    the same model, parameters, region, cells and plan."""
    if _db_call(_lib.cm_db_resume, path, model, params, plugins, region, cells, split, extend,
                escape_below, threads, max_steps, mem, command, progress, kw, ranks):
        return Database(path)
    return None


def _grown_options(threads, max_steps, mem, command):
    o = _DbOptions()
    o.threads, o.max_steps, o.mem, o.command = threads, max_steps, mem, _text(command)
    return o


def _rect(region):
    lo = (ctypes.c_double * len(region))(*[float(a) for a, _ in region])
    hi = (ctypes.c_double * len(region))(*[float(b) for _, b in region])
    return lo, hi


def add_box(path, region, threads=0, max_steps=0, mem=0, command=None):
    """Computes the cells of region [(lo, hi), ...] (every dimension of the
    file) that the database at path lacks, joined and committed as new
    regions; returns how many cells were new."""
    n = ctypes.c_uint64()
    _call(_lib.cm_db_add_box, _text(os.fspath(path)), *_rect(region),
          ctypes.byref(_grown_options(threads, max_steps, mem, command)), ctypes.byref(n))
    return n.value


def extend(path, tile, steps, threads=0, max_steps=0, mem=0, command=None):
    """Adaptive extension (thesis 4.6.4) of the database at path by up to
    steps tiles of tile's size [(lo, hi), ...], each where the most
    sequences escape, as `cellmap solve --extend` does; returns the steps
    done."""
    n = ctypes.c_int()
    _call(_lib.cm_db_extend, _text(os.fspath(path)), *_rect(tile), int(steps),
          ctypes.byref(_grown_options(threads, max_steps, mem, command)), ctypes.byref(n))
    return n.value


def export(path, labels=None, steps=None, view=None, by="attractors"):
    """The cells of a database (those whose centres lie in view [(lo, hi),
    ...], default all) as .npy arrays with JSON sidecars, as `cellmap export
    --labels --steps [--window]` writes them."""
    if by not in ("attractors", "groups"):
        raise ValueError("export(): by=%r: 'attractors' or 'groups'" % (by,))
    lo = hi = None
    if view is not None:
        lo = (ctypes.c_double * len(view))(*[float(a) for a, _ in view])
        hi = (ctypes.c_double * len(view))(*[float(b) for _, b in view])
    _call(_lib.cm_db_export, _text(os.fspath(path)), lo, hi,
          _text(None if labels is None else os.fspath(labels)),
          _text(None if steps is None else os.fspath(steps)), int(by == "groups"))


class Session:
    """An explore session on a database that grows as the view moves: each
    move computes exactly the cells it uncovers, joins them and commits
    them, as `cellmap explore` does. A new file needs model= and cell_size=.

        with cellmap.Session("pd.cmdb", model="microchaos-pd", alpha=0.078,
                             cell_size=(0.5, 0.08)) as s:
            s.view([(0, 50), (-4, 4)])
            s.pan(0, 5)                  # by 5 in the first coordinate
            s.figure("view.png")
            labels = s.read().attractor_labels
    """

    def __init__(self, path, model=None, params=None, plugins=(), cell_size=None, origin=None,
                 depth=None, max_steps=0, threads=0, mem=0, command=None, **kw):
        self.models = Models(plugins) if plugins else None
        o = _SessionOptions()
        self._keep = [_text(model), _text(_params_text(params, kw)) if model else None,
                      _text(depth), _text(command)]
        o.model, o.params, o.depth, o.command = self._keep
        o.set = self.models._h if self.models else None
        for d, w in enumerate(cell_size or ()):
            o.cell_size[d] = float(w)
        for d, x in enumerate(origin or ()):
            o.origin[d] = float(x)
        o.max_steps, o.threads, o.mem = max_steps, threads, mem
        self._h = _P()
        _call(_lib.cm_session_open, _text(os.fspath(path)), ctypes.byref(o),
              ctypes.byref(self._h))

    def _moved(self, fn, *args):
        new = ctypes.c_uint64()
        _call(fn, self._h, *args, ctypes.byref(new))
        return new.value

    def view(self, region):
        """Moves the view to [(x0, x1), (y0, y1)]; returns the new cells computed."""
        lo = (ctypes.c_double * 2)(*[float(a) for a, _ in region] + [0.0] * (2 - len(region)))
        hi = (ctypes.c_double * 2)(*[float(b) for _, b in region] + [0.0] * (2 - len(region)))
        return self._moved(_lib.cm_session_view, lo, hi)

    @property
    def bounds(self):
        """The view [(x0, x1), (y0, y1)], or None before the first."""
        lo, hi = (ctypes.c_double * 2)(), (ctypes.c_double * 2)()
        if _lib.cm_session_bounds(self._h, lo, hi) != 0:
            return None
        return list(zip(lo, hi))

    def pan(self, d, by):
        """Moves the view by `by` (state units) in coordinate d; new cells computed."""
        return self._moved(_lib.cm_session_pan, int(d), float(by))

    def zoom(self, factor):
        """Zooms about the view's centre (2: twice as close); new cells computed."""
        return self._moved(_lib.cm_session_zoom, float(factor))

    def extend(self, steps=1):
        """`extend auto steps`; returns the steps done."""
        done = ctypes.c_int()
        _call(_lib.cm_session_extend, self._h, int(steps), ctypes.byref(done))
        return done.value

    def read(self):
        """The view's cells as a Result (labels, steps, attractors)."""
        h = _P()
        _call(_lib.cm_session_read, self._h, ctypes.byref(h))
        return Result(h, self)

    def query(self, x):
        """What the session knows of the cell holding state x (a coordinate
        per dimension): {'cell', 'centre', 'label' (-1: not computed), 'step',
        'attractor'}, as read() gives them for that cell; nothing is computed."""
        x = [float(v) for v in x]
        info = _CellInfo()
        _call(_lib.cm_session_query, self._h, (ctypes.c_double * len(x))(*x), ctypes.byref(info))
        dim = len(x)
        return {"cell": [int(info.cell[d]) for d in range(dim)],
                "centre": [info.centre[d] for d in range(dim)],
                "label": ctypes.c_int32(info.label).value, "step": ctypes.c_int32(info.step).value,
                "attractor": info.attractor}

    def figure(self, png=None, **options):
        """The view's figure, as `render` in a session draws it (options as
        Result.figure; layers default to basin and attractors, as render's)."""
        options.setdefault("layers", ("basin", "attractors"))
        o, keep = _figure_options(png, options)
        _call(_lib.cm_session_figure, self._h, ctypes.byref(o))

    def close(self):
        """Saves the view and the attractors and closes the database."""
        if getattr(self, "_h", None):
            h, self._h = self._h, None
            _call(_lib.cm_session_close, h)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except CellmapError:
            pass


from . import analysis  # noqa: E402 - the drivers build on the definitions above
