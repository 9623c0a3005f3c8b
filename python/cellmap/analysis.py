"""The analysis drivers of libcellmap (cm_analysis_* in cellmap/cellmap.h):
the commands stability, partition, amplitude, horseshoe, escape,
equilibria, periodic, exponents, simulate (and series, simulate's time
series of flows and chip-bue), bifurcation, lyapunov, sweep and continue
as functions. Each computes what
the command computes and writes the same files (csv=, png=, byte for
byte); it returns the table as a numpy structured array (columns by name,
as the CSV's header names them), read from csv= or from a temporary file.

Every function takes, besides its own settings:
    model=None      the command's model, or another (lyapunov, sweep)
    params=None     its parameters: "k=v,..." or a dict
    plugins=()      shared objects with more models (examples/plugin)
    csv=None, png=None, size=None (width, height), threads=0

An axis is (lo, hi, n): n values at the centres of n cells over lo..hi,
as the commands' NAME=LO:HI:N; a named axis is (name, lo, hi, n).

    t = cellmap.analysis.bifurcation(("S", 0.02, 0.4, 50), runs=4, png="bif.png")[0]
    print(t["S"][:5], t["x"][:5])
"""
import ctypes
import math
import os
import tempfile

import numpy as np

from . import CellmapError, Models, _call, _lib, _text, _P, _DOUBLES  # noqa: F401

__all__ = ["stability", "partition", "amplitude", "horseshoe", "escape", "equilibria",
           "periodic", "exponents", "series", "simulate", "bifurcation", "lyapunov", "sweep",
           "continuation"]


class _Axis(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("lo", ctypes.c_double), ("hi", ctypes.c_double),
                ("n", ctypes.c_int)]


class _Analysis(ctypes.Structure):
    _fields_ = [("set", _P), ("model", ctypes.c_char_p), ("params", ctypes.c_char_p),
                ("csv", ctypes.c_char_p), ("png", ctypes.c_char_p), ("width", ctypes.c_int),
                ("height", ctypes.c_int), ("threads", ctypes.c_int)]


class _Horseshoe(ctypes.Structure):
    _fields_ = [("m0", ctypes.c_int64), ("m1", ctypes.c_int64), ("periods", ctypes.c_int),
                ("sweep", ctypes.POINTER(_Axis)), ("crisis", ctypes.c_int)]


class _Escape(ctypes.Structure):
    _fields_ = [("I0", ctypes.c_double), ("sweep", ctypes.POINTER(_Axis)),
                ("cells", ctypes.c_long), ("ensemble", ctypes.c_long)]


class _Branch(ctypes.Structure):
    _fields_ = [("start", _DOUBLES), ("n_from", ctypes.c_int), ("name", ctypes.c_char_p),
                ("lo", ctypes.c_double), ("hi", ctypes.c_double), ("direction", ctypes.c_int),
                ("ds_max", ctypes.c_double), ("max_points", ctypes.c_int)]


class _Equilibria(ctypes.Structure):
    _fields_ = [("b", _Branch), ("curve", ctypes.POINTER(_Axis))]


class _Periodic(ctypes.Structure):
    _fields_ = [("b", _Branch), ("settle", ctypes.c_int), ("period", ctypes.c_int),
                ("cascade", ctypes.c_int)]


class _Exponents(ctypes.Structure):
    _fields_ = [("start", ctypes.c_double * 6), ("n_from", ctypes.c_int), ("of_map", ctypes.c_int),
                ("count", ctypes.c_int), ("time", ctypes.c_double),
                ("transient", ctypes.c_double), ("renorm", ctypes.c_double),
                ("iterations", ctypes.c_long), ("skip", ctypes.c_long),
                ("samples", ctypes.c_int), ("gs", ctypes.c_int), ("sync", ctypes.c_int),
                ("q_max", ctypes.c_double)]


class _ExponentsOut(ctypes.Structure):
    _fields_ = [("count", ctypes.c_int), ("lam", ctypes.c_double * 6),
                ("kaplan_yorke", ctypes.c_double), ("mean_flight", ctypes.c_double)]


class _Series(ctypes.Structure):
    _fields_ = [("start", ctypes.c_double * 12), ("n_from", ctypes.c_int),
                ("time", ctypes.c_double), ("skip", ctypes.c_double), ("dt", ctypes.c_double),
                ("of", ctypes.c_char_p), ("time_unit", ctypes.c_double),
                ("fmax", ctypes.c_double), ("spectrum_csv", ctypes.c_char_p),
                ("returns", ctypes.c_int)]


class _Embedding(ctypes.Structure):
    _fields_ = [("input", ctypes.c_char_p), ("of", ctypes.c_char_p),
                ("start", ctypes.c_double * 12), ("n_from", ctypes.c_int),
                ("time", ctypes.c_double), ("transient", ctypes.c_double), ("dt", ctypes.c_double),
                ("values", ctypes.c_int), ("dim_lo", ctypes.c_int), ("dim_hi", ctypes.c_int),
                ("lag", ctypes.c_int), ("steps", ctypes.c_int), ("fnn_dim", ctypes.c_int),
                ("theiler", ctypes.c_int), ("radius", ctypes.c_double * 8),
                ("n_radius", ctypes.c_int), ("fit_lo", ctypes.c_int), ("fit_hi", ctypes.c_int),
                ("time_unit", ctypes.c_double)]


class _EmbeddingOut(ctypes.Structure):
    _fields_ = [("n", ctypes.c_size_t), ("interval", ctypes.c_double),
                ("embedding_dim", ctypes.c_int), ("fnn_dim", ctypes.c_int),
                ("false_neighbours", ctypes.c_double * 64), ("lam", ctypes.c_double),
                ("spread", ctypes.c_double), ("lambda_per_time", ctypes.c_double)]


class _Measure(ctypes.Structure):
    _fields_ = [("file", ctypes.c_char_p), ("window", ctypes.c_char_p),
                ("box", ctypes.c_int * 8), ("n_box", ctypes.c_int), ("eps_lo", ctypes.c_int),
                ("eps_hi", ctypes.c_int), ("wada_radius", ctypes.c_int),
                ("wada_required", ctypes.c_int), ("to", ctypes.c_char_p),
                ("mem", ctypes.c_uint64), ("samples", ctypes.c_uint64),
                ("seed", ctypes.c_uint64), ("threads", ctypes.c_int),
                ("orbit_eps_lo", ctypes.c_double), ("orbit_eps_hi", ctypes.c_double)]


class _MeasureOut(ctypes.Structure):
    _fields_ = [("cells", ctypes.c_uint64), ("computed", ctypes.c_uint64), ("sb", ctypes.c_double),
                ("sbb", ctypes.c_double), ("alpha", ctypes.c_double),
                ("alpha_r2", ctypes.c_double), ("wada_basins", ctypes.c_int),
                ("wada_fraction", ctypes.c_double), ("sampled", ctypes.c_uint64),
                ("sampled_as_labelled", ctypes.c_uint64), ("samples_agree", ctypes.c_int),
                ("orbit_alpha", ctypes.c_double), ("orbit_alpha_r2", ctypes.c_double)]


class _Simulate(ctypes.Structure):
    _fields_ = [("x", ctypes.c_double), ("v", ctypes.c_double), ("t0", ctypes.c_double),
                ("periods", ctypes.c_int), ("skip", ctypes.c_int)]


class _Bifurcation(ctypes.Structure):
    _fields_ = [("sweep", _Axis), ("runs", ctypes.c_int), ("transient", ctypes.c_int),
                ("record", ctypes.c_int), ("seed", ctypes.c_longlong),
                ("runs_csv", ctypes.c_char_p)]


class _Lyapunov(ctypes.Structure):
    _fields_ = [("x", _Axis), ("y", _Axis), ("periods", ctypes.c_int), ("d0", ctypes.c_double),
                ("start", _DOUBLES), ("n_from", ctypes.c_int),
                ("curves", ctypes.POINTER(ctypes.c_char_p)), ("n_curves", ctypes.c_int)]


class _Sweep(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("values", _DOUBLES), ("n_values", ctypes.c_int),
                ("region", ctypes.c_char_p), ("cells", ctypes.POINTER(ctypes.c_int64)),
                ("n_cells", ctypes.c_int), ("near_lo", _DOUBLES), ("near_hi", _DOUBLES),
                ("n_near", ctypes.c_int), ("refine", ctypes.c_int), ("max_steps", ctypes.c_int),
                ("by_groups", ctypes.c_int), ("fractions", ctypes.c_char_p),
                ("match_within", ctypes.c_double), ("keep", ctypes.c_char_p),
                ("no_seeds", ctypes.c_int)]


class _Continue(ctypes.Structure):
    _fields_ = [("vary", ctypes.c_char_p), ("lo", ctypes.c_double), ("hi", ctypes.c_double),
                ("direction", ctypes.c_int), ("switch_pd", ctypes.c_int),
                ("start", ctypes.POINTER(ctypes.c_double * 3)), ("n_from", ctypes.c_int),
                ("period", ctypes.c_int), ("max_points", ctypes.c_int),
                ("events", ctypes.c_char_p), ("curve", ctypes.c_char_p),
                ("lo2", ctypes.c_double), ("hi2", ctypes.c_double), ("curves", ctypes.c_char_p)]


def _sig(name, *args):
    f = getattr(_lib, name)
    f.restype = ctypes.c_int
    f.argtypes = [ctypes.POINTER(_Analysis)] + list(args) + [ctypes.c_char_p, ctypes.c_size_t]


_AXIS = ctypes.POINTER(_Axis)
_sig("cm_analysis_stability", _AXIS, _AXIS)
_sig("cm_analysis_partition")
_sig("cm_analysis_amplitude", _AXIS, ctypes.c_int, ctypes.c_double)
for _name, _opts in (("horseshoe", _Horseshoe), ("escape", _Escape),
                     ("equilibria", _Equilibria), ("periodic", _Periodic),
                     ("simulate", _Simulate), ("bifurcation", _Bifurcation),
                     ("lyapunov", _Lyapunov), ("sweep", _Sweep), ("continue", _Continue)):
    _sig("cm_analysis_" + _name, ctypes.POINTER(_opts))
_sig("cm_analysis_series", ctypes.POINTER(_Series))
_sig("cm_analysis_exponents", ctypes.POINTER(_Exponents), ctypes.POINTER(_ExponentsOut))
_sig("cm_analysis_embedding", ctypes.POINTER(_Embedding), ctypes.POINTER(_EmbeddingOut))
_sig("cm_analysis_measure", ctypes.POINTER(_Measure), ctypes.POINTER(_MeasureOut))
for _name, _opts in (("horseshoe", _Horseshoe), ("escape", _Escape),
                     ("equilibria", _Equilibria), ("periodic", _Periodic),
                     ("exponents", _Exponents), ("series", _Series), ("embedding", _Embedding),
                     ("measure", _Measure),
                     ("simulate", _Simulate), ("bifurcation", _Bifurcation),
                     ("lyapunov", _Lyapunov), ("continue", _Continue)):
    getattr(_lib, "cm_%s_defaults" % _name).restype = _opts
    getattr(_lib, "cm_%s_defaults" % _name).argtypes = []


def _params(params):
    if params is None or isinstance(params, str):
        return params
    return ",".join("%s=%s" % (k, v if isinstance(v, str) else repr(float(v)))
                    for k, v in params.items())


def _axis(value, name=None, what="axis"):
    """(lo, hi, n) or (name, lo, hi, n) as a C axis."""
    try:
        if name is None:
            name, lo, hi, n = value
        else:
            lo, hi, n = value[-3:]
        return _Axis(_text(name), float(lo), float(hi), int(n))
    except (TypeError, ValueError):
        raise ValueError("%s %r: give %s(lo, hi, n)"
                         % (what, value, "" if name is not None else "(name, ")) from None


def _path(p):
    return None if p is None else _text(os.fspath(p))


class _Run:
    """One call: the common part, temporary files for tables not asked for,
    and the tables read back after the call."""

    def __init__(self, model, params, plugins, csv, png, size, threads):
        self.tmp = tempfile.TemporaryDirectory(prefix="cellmap-")
        self.models = Models(plugins) if plugins else None
        self.csv = os.fspath(csv) if csv is not None else os.path.join(self.tmp.name, "t.csv")
        w, h = size or (0, 0)
        self.keep = [_text(model), _text(_params(params))]
        self.a = _Analysis(self.models._h if self.models else None, self.keep[0], self.keep[1],
                           _path(self.csv), _path(png), int(w), int(h), int(threads))

    def table_path(self, given, name):
        return os.fspath(given) if given is not None else os.path.join(self.tmp.name, name)

    def call(self, fn, *args):
        _call(fn, ctypes.byref(self.a), *args)

    @staticmethod
    def read(path):
        if path == "-":
            return None
        with open(path, encoding="utf-8") as f:
            rows = f.read().splitlines()
        if len(rows) <= 1:
            names = rows[0].split(",") if rows else []
            return np.zeros(0, dtype=[(n, float) for n in names])
        return np.atleast_1d(np.genfromtxt(rows, delimiter=",", names=True, dtype=None,
                                           encoding="utf-8", deletechars=""))

    def close(self):
        self.tmp.cleanup()


def _run(common, fn, *args, second=None):
    """Calls fn with the common part and args; returns the table, or, with
    second = (options, field, path or None), it and the table the options'
    field names (a temporary file unless a path is given)."""
    r = _Run(**common)
    try:
        path = None
        if second is not None:
            options, field, given = second
            path = r.table_path(given, field + ".csv")
            setattr(options, field, _path(path))
        r.call(fn, *args)
        return r.read(r.csv) if path is None else (r.read(r.csv), r.read(path))
    finally:
        r.close()


def _common(model=None, params=None, plugins=(), csv=None, png=None, size=None, threads=0):
    return dict(model=model, params=params, plugins=plugins, csv=csv, png=png, size=size,
                threads=threads)


def stability(P=None, alpha=None, **common):
    """microchaos-pd's charts (`cellmap stability`): P and alpha as (lo, hi, n)."""
    p = ctypes.byref(_axis(P, "P", "P")) if P is not None else None
    a = ctypes.byref(_axis(alpha, "alpha", "alpha")) if alpha is not None else None
    return _run(_common(**common), _lib.cm_analysis_stability, p, a)


def partition(**common):
    """microchaos-delay's Markov partition (`cellmap partition`)."""
    return _run(_common(**common), _lib.cm_analysis_partition)


def amplitude(omega, periods=0, ymax=0.0, **common):
    """friction-oscillator's amplitude-frequency diagram (`cellmap amplitude`)."""
    return _run(_common(**common), _lib.cm_analysis_amplitude,
                ctypes.byref(_axis(omega, "Omega", "omega")), int(periods), float(ymax))


def horseshoe(m=None, periods=None, sweep=None, crisis=False, **common):
    """microchaos-pd's horseshoes (`cellmap horseshoe`): lines m = (m0, m1)."""
    o = _lib.cm_horseshoe_defaults()
    if m is not None:
        o.m0, o.m1 = int(m[0]), int(m[1])
    if periods is not None:
        o.periods = int(periods)
    ax = _axis(sweep, "P", "sweep") if sweep is not None else None
    o.sweep = ctypes.pointer(ax) if ax is not None else None
    o.crisis = int(bool(crisis))
    return _run(_common(**common), _lib.cm_analysis_horseshoe, ctypes.byref(o))


def escape(I0=None, sweep=None, cells=None, ensemble=None, **common):
    """microchaos-1d-friction's transient chaos (`cellmap escape`); sweep:
    (name, lo, hi, n) of a, b or I0."""
    o = _lib.cm_escape_defaults()
    o.I0 = float(I0) if I0 is not None else 0.0
    ax = _axis(sweep, what="sweep") if sweep is not None else None
    o.sweep = ctypes.pointer(ax) if ax is not None else None
    if cells is not None:
        o.cells = int(cells)
    if ensemble is not None:
        o.ensemble = int(ensemble)
    return _run(_common(**common), _lib.cm_analysis_escape, ctypes.byref(o))


def _branch(b, start, branch, direction, ds_max, max_points):
    """Fills the cm_branch b; returns what must live as long as it."""
    st = (ctypes.c_double * len(start))(*map(float, start))
    b.start, b.n_from = st, len(start)
    name = None
    if branch is not None:
        try:
            name, lo, hi = branch
            name = _text(name)
            b.name, b.lo, b.hi = name, float(lo), float(hi)
        except (TypeError, ValueError):
            raise ValueError("branch %r: give (name, lo, hi)" % (branch,)) from None
    b.direction = int(direction)
    if ds_max is not None:
        b.ds_max = float(ds_max)
    if max_points is not None:
        b.max_points = int(max_points)
    return st, name


def equilibria(start, branch=None, direction=0, ds_max=None, max_points=None, curve=None,
               **common):
    """Equilibria of a flow (`cellmap equilibria`; model chip-4d unless
    named): Newton from start (the flow's coordinates) and the eigenvalues;
    branch = (name, lo, hi): the branch in that parameter with its folds
    and Hopf points (direction +1 or -1: one way only); curve = (name, lo,
    hi, n): the branch's Hopf points at each of n values of a second
    parameter. The rows: kind, the parameters, the state, re_k/im_k,
    unstable, omega."""
    o = _lib.cm_equilibria_defaults()
    keep = _branch(o.b, start, branch, direction, ds_max, max_points)
    ax = _axis(curve, what="curve") if curve is not None else None
    o.curve = ctypes.pointer(ax) if ax is not None else None
    table = _run(_common(**common), _lib.cm_analysis_equilibria, ctypes.byref(o))
    del keep
    return table


def periodic(start, settle=0, period=1, branch=None, direction=0, ds_max=None,
             max_points=None, cascade=0, **common):
    """Periodic orbits of a map (`cellmap periodic`; model chip-4d unless
    named): Newton on P^period from start (after settle iterates) and the
    multipliers; branch = (name, lo, hi): the branch in that parameter with
    its folds, period doublings and Neimark-Sacker points (direction +1 or
    -1: one way only); cascade = n: n doublings, each next branch switched
    to at the last (needs a direction). The rows: kind, period, the
    parameter, the state, re_k/im_k, outside."""
    o = _lib.cm_periodic_defaults()
    keep = _branch(o.b, start, branch, direction, ds_max, max_points)
    o.settle, o.period, o.cascade = int(settle), int(period), int(cascade)
    table = _run(_common(**common), _lib.cm_analysis_periodic, ctypes.byref(o))
    del keep
    return table


def _start(o, start):
    """start (None: the model's default) into o.start and o.n_from."""
    if start is None:
        return
    if len(start) > len(o.start):
        raise ValueError("start: at most %d coordinates" % len(o.start))
    o.n_from = len(start)
    for i, v in enumerate(start):
        o.start[i] = float(v)


def exponents(start=None, of_map=False, count=0, time=None, transient=None, renorm=None,
              iterations=None, skip=None, samples=None, gs=None, sync=False, q_max=None,
              **common):
    """The Lyapunov spectrum of one orbit (`cellmap exponents`; model chip-4d
    unless named): a flow's by its variational equations (time, transient,
    renorm), a map's (of_map=True, or a map model) by the QR of its Jacobian
    (iterations, skip), chip-bue's by Farmer's map (samples, gs) or the
    synchronisation estimate (sync=True, q_max). Returns (result, table):
    result a dict of lambda (decreasing), kaplan_yorke (None when more
    exponents are needed) and mean_flight (a flow's map), the table the
    running estimates (t, lambda_1.., kaplan_yorke)."""
    o = _lib.cm_exponents_defaults()
    _start(o, start)
    o.of_map, o.count, o.sync = int(bool(of_map)), int(count), int(bool(sync))
    for key, value, kind in (("time", time, float), ("transient", transient, float),
                             ("renorm", renorm, float), ("iterations", iterations, int),
                             ("skip", skip, int), ("samples", samples, int), ("gs", gs, int),
                             ("q_max", q_max, float)):
        if value is not None:
            setattr(o, key, kind(value))
    res = _ExponentsOut()
    table = _run(_common(**common), _lib.cm_analysis_exponents, ctypes.byref(o),
                 ctypes.byref(res))
    ky = res.kaplan_yorke
    return ({"lambda": [res.lam[i] for i in range(res.count)],
             "kaplan_yorke": None if math.isnan(ky) else ky,
             "mean_flight": None if math.isnan(res.mean_flight) else res.mean_flight}, table)


def embedding(of, input=None, start=None, time=None, transient=None, dt=None, values="max",
              dims=None, lag=None, steps=None, fnn_dim=None, theiler=None, radius=None, fit=None,
              time_unit=0.0, **common):
    """The largest Lyapunov exponent and embedding dimension of one series
    (`cellmap exponents --series`): the column `of` of the CSV file input,
    or the coordinate `of` of the model's orbit (chip-4d unless named; from
    start, over time after transient, every dt); values "max", "min" or
    "all"; dims M or (M, M2); radius a list of fractions of the range; fit
    (K0, K1). Returns (result, curves): result a dict of n, interval,
    embedding_dim (None: none), false_neighbours, lambda (per value),
    spread and lambda_per_time; curves the table dim, radius, k, S."""
    o = _lib.cm_embedding_defaults()
    _start(o, start)
    if values not in ("max", "min", "all"):
        raise ValueError("values %r: give 'max', 'min' or 'all'" % (values,))
    o.values = {"max": 1, "min": -1, "all": 0}[values]
    keep = [_text(of), _path(input)]
    o.of, o.input = keep
    for key, value, kind in (("time", time, float), ("transient", transient, float),
                             ("dt", dt, float), ("lag", lag, int), ("steps", steps, int),
                             ("fnn_dim", fnn_dim, int), ("theiler", theiler, int)):
        if value is not None:
            setattr(o, key, kind(value))
    if dims is not None:
        o.dim_lo, o.dim_hi = (int(dims), int(dims)) if isinstance(dims, int) else map(int, dims)
    if fit is not None:
        o.fit_lo, o.fit_hi = map(int, fit)
    if radius is not None:
        radius = [float(r) for r in radius]
        if not 1 <= len(radius) <= 8:
            raise ValueError("radius: give 1..8 fractions of the series' range")
        o.radius[:len(radius)] = radius
        o.n_radius = len(radius)
    o.time_unit = float(time_unit)
    res = _EmbeddingOut()
    curves = _run(_common(**common), _lib.cm_analysis_embedding, ctypes.byref(o),
                  ctypes.byref(res))
    return ({"n": res.n, "interval": None if math.isnan(res.interval) else res.interval,
             "embedding_dim": res.embedding_dim or None,
             "false_neighbours": list(res.false_neighbours[:res.fnn_dim]),
             "lambda": res.lam, "spread": res.spread,
             "lambda_per_time": None if math.isnan(res.lambda_per_time) else res.lambda_per_time},
            curves)


def measure(file, window=None, entropy=(3, 5, 7, 9), uncertainty=(1, 16), wada=5,
            wada_required=False, to=None, mem=None, samples=0, seed=1, threads=0,
            orbit_uncertainty=None, csv=None, png=None, size=None):
    """A .cmdb file's basins measured (`cellmap measure`): entropy the box
    sizes of basin entropy (() for none), uncertainty (E0, E1) the eps range
    (None for none), wada the Wada test's radius (0 for none), to a second
    file on the same lattice for the tipping probabilities, samples random
    states (seed their stream) followed by their true orbits (and with
    orbit_uncertainty (E0, E1) the uncertain fractions by them), png the figure
    of a 2-D window. Returns
    (summary, table): summary a dict of cells, computed, sb, sbb (means over
    the boxes), alpha, alpha_r2, wada_basins and wada_fraction, sampled (in
    computed cells), sampled_as_labelled, samples_agree, orbit_alpha and
    orbit_alpha_r2 (None where not measured); table the rows measure,
    scale, value (share, sampled, sb, sbb, uncertain, orbit_uncertain, wada,
    tipping)."""
    o = _lib.cm_measure_defaults()
    keep = [_path(file), _text(window) if window is not None else None, _path(to)]
    o.file, o.window, o.to = keep
    entropy = [int(b) for b in entropy]
    if len(entropy) > 8:
        raise ValueError("entropy: at most 8 box sizes")
    o.box[:len(entropy)] = entropy
    o.n_box = len(entropy)
    o.eps_lo, o.eps_hi = (0, 0) if uncertainty is None else map(int, uncertainty)
    o.wada_radius, o.wada_required = int(wada), int(bool(wada_required))
    if mem is not None:
        o.mem = int(mem)
    o.samples, o.seed, o.threads = int(samples), int(seed), int(threads)
    if orbit_uncertainty is not None:
        o.orbit_eps_lo, o.orbit_eps_hi = map(float, orbit_uncertainty)
    res = _MeasureOut()
    table = _run(_common(csv=csv, png=png, size=size), _lib.cm_analysis_measure, ctypes.byref(o),
                 ctypes.byref(res))
    nan = lambda v: None if math.isnan(v) else v
    return ({"cells": res.cells, "computed": res.computed, "sb": nan(res.sb), "sbb": nan(res.sbb),
             "alpha": nan(res.alpha), "alpha_r2": nan(res.alpha_r2),
             "wada_basins": res.wada_basins or None,
             "wada_fraction": nan(res.wada_fraction) if res.wada_basins else None,
             "sampled": res.sampled or None,
             "sampled_as_labelled": res.sampled_as_labelled if res.sampled else None,
             "samples_agree": bool(res.samples_agree) if res.sampled else None,
             "orbit_alpha": nan(res.orbit_alpha), "orbit_alpha_r2": nan(res.orbit_alpha_r2)},
            table)


def series(model, start=None, time=None, skip=None, dt=None, of=None, time_unit=0.0, fmax=0.0,
           spectrum_csv=None, returns=False, **common):
    """The time series of a flow model or chip-bue (`cellmap simulate
    --model FLOW`) and the power spectrum (FFTW) of coordinate `of`:
    returns (samples, spectrum) tables; time_unit (seconds per unit) adds
    frequency_hz; returns=True adds the return map at the section to png."""
    o = _lib.cm_series_defaults()
    _start(o, start)
    for key, value in (("time", time), ("skip", skip), ("dt", dt)):
        if value is not None:
            setattr(o, key, float(value))
    o.of = _text(of) if of is not None else None
    o.time_unit, o.fmax, o.returns = float(time_unit), float(fmax), int(bool(returns))
    return _run(_common(model=model, **common), _lib.cm_analysis_series, ctypes.byref(o),
                second=(o, "spectrum_csv", spectrum_csv))


def simulate(start=(0.0, 0.0), t0=None, periods=20, skip=0, **common):
    """A trajectory of friction-oscillator (`cellmap simulate`) from start (x, v)."""
    o = _Simulate(float(start[0]), float(start[1]), math.nan if t0 is None else float(t0),
                  int(periods), int(skip))
    return _run(_common(**common), _lib.cm_analysis_simulate, ctypes.byref(o))


def bifurcation(sweep, runs=None, transient=None, record=None, seed=None, runs_csv=None,
                **common):
    """friction-oscillator's brute-force diagram (`cellmap bifurcation`);
    returns (points, runs) tables."""
    o = _lib.cm_bifurcation_defaults()
    o.sweep = _axis(sweep, what="sweep")
    for key, value in (("runs", runs), ("transient", transient), ("record", record),
                       ("seed", seed)):
        if value is not None:
            setattr(o, key, int(value))
    return _run(_common(**common), _lib.cm_analysis_bifurcation, ctypes.byref(o),
                second=(o, "runs_csv", runs_csv))


def lyapunov(x, y, periods=None, d0=None, start=None, curves=(), **common):
    """The largest Lyapunov exponent over a grid (`cellmap lyapunov`): x, y
    as (name, lo, hi, n); start: a map model's start state."""
    o = _lib.cm_lyapunov_defaults()
    o.x, o.y = _axis(x, what="x"), _axis(y, what="y")
    if periods is not None:
        o.periods = int(periods)
    if d0 is not None:
        o.d0 = float(d0)
    st = (ctypes.c_double * len(start))(*map(float, start)) if start else None
    o.start, o.n_from = st, len(start) if start else 0
    cv = (ctypes.c_char_p * max(1, len(curves)))(*[_path(c) for c in curves])
    o.curves, o.n_curves = cv, len(curves)
    return _run(_common(**common), _lib.cm_analysis_lyapunov, ctypes.byref(o))


def sweep(name, values, region=None, cells=None, near=None, refine=0, max_steps=0,
          by="attractors", match_within=0.0, fractions_csv=None, keep=None, seeds=True,
          **common):
    """A model solved at each value of one parameter (`cellmap sweep`):
    region [(lo, hi), ...], cells (n0, n1, ...), the window near [(lo, hi), ...];
    its attractors tracked from value to value (match_within: their distance,
    a share of the region). Returns (counts, fractions) tables: fractions the
    tracked attractors' basin shares per value (None with by="groups"; a
    temporary file unless fractions_csv names one); png= draws them stacked;
    keep= a directory where each value is solved into NAME=VALUE.cmdb; seeds=False
    leaves births and deaths where the lattice shows them."""
    if by not in ("attractors", "groups"):
        raise ValueError("sweep(): by=%r: 'attractors' or 'groups'" % (by,))
    vals = (ctypes.c_double * len(values))(*map(float, values))
    region_text = ",".join("%r:%r" % (float(a), float(b)) for a, b in region) if region else None
    cl = (ctypes.c_int64 * len(cells))(*map(int, cells)) if cells else None
    lo = (ctypes.c_double * len(near))(*[float(a) for a, _ in near]) if near else None
    hi = (ctypes.c_double * len(near))(*[float(b) for _, b in near]) if near else None
    o = _Sweep(_text(name), vals, len(values), _text(region_text), cl, len(cells or ()), lo, hi,
               len(near or ()), int(refine), int(max_steps), int(by == "groups"), None,
               float(match_within), _path(keep), int(not seeds))
    if by == "groups":
        return _run(_common(**common), _lib.cm_analysis_sweep, ctypes.byref(o)), None
    return _run(_common(**common), _lib.cm_analysis_sweep, ctypes.byref(o),
                second=(o, "fractions", fractions_csv))


def continuation(vary, direction="up", switch=False, starts=(), period=0, max_points=0,
                 curve=None, curves=None, events=None, **common):
    """Branches of friction-oscillator's periodic solutions (`cellmap
    continue`): vary (name, lo, hi); direction "up", "down" or "both";
    starts [(x, v, value), ...] (NaN x: simulate; NaN value: the model's);
    curve (name2, lo2, hi2) with curves= a CSV path. Returns (points, events)."""
    directions = {"up": 1, "down": -1, "both": 0}
    if direction not in directions:
        raise ValueError("continuation(): direction=%r: 'up', 'down' or 'both'" % (direction,))
    o = _lib.cm_continue_defaults()
    name, lo, hi = vary
    keep = [_text(name), _text(curve[0]) if curve else None, _path(curves)]
    o.vary, o.lo, o.hi = keep[0], float(lo), float(hi)
    o.direction, o.switch_pd = directions[direction], int(bool(switch))
    arr = ((ctypes.c_double * 3) * max(1, len(starts)))(
        *[(ctypes.c_double * 3)(*map(float, s)) for s in starts])
    o.start, o.n_from = ctypes.cast(arr, ctypes.POINTER(ctypes.c_double * 3)), len(starts)
    o.period, o.max_points = int(period), int(max_points)
    if curve:
        o.curve, o.lo2, o.hi2 = keep[1], float(curve[1]), float(curve[2])
    o.curves = keep[2]
    return _run(_common(**common), _lib.cm_analysis_continue, ctypes.byref(o),
                second=(o, "events", events))
