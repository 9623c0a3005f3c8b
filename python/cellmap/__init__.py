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

The library is found through $CELLMAP_LIB, then next to an installed
cellmap (PREFIX/lib), then the system's library path.
"""
import ctypes
import ctypes.util
import os

import numpy as np

__all__ = ["System", "Models", "Result", "Database", "solve", "open", "models",
           "CellmapError", "LABEL_NONE", "version"]

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
    here = os.path.dirname(os.path.abspath(__file__))
    # PREFIX/lib/pythonX.Y/site-packages/cellmap -> PREFIX/lib
    for up in (3, 4):
        base = os.path.normpath(os.path.join(here, *[".."] * up))
        for name in ("libcellmap.so.0", "libcellmap.so"):
            path = os.path.join(base, name)
            if os.path.exists(path):
                yield path
    found = ctypes.util.find_library("cellmap")
    if found:
        yield found
    yield "libcellmap.so.0"


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
        """Writes the basin figure (0, 0: 1000 pixels on the longer side)."""
        _call(_lib.cm_result_png, self._h, _text(os.fspath(path)), width, height)

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
    _call(_lib.cm_solve, system._h, ctypes.byref(g), ctypes.byref(opt), ctypes.byref(h))
    return Result(h, system)


class Database:
    """A cluster database (.cmdb) that `cellmap solve --db` or `explore` wrote,
    opened read-only."""

    def __init__(self, path):
        self._h = _P()
        _call(_lib.cm_db_open, _text(os.fspath(path)), ctypes.byref(self._h))
        self.model = _lib.cm_db_model(self._h).decode()
        self.params = _lib.cm_db_params(self._h).decode()
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
