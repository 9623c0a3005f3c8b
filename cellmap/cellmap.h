/* cellmap/cellmap.h - libcellmap: cell mapping of dynamical systems from C.
 *
 * What it does: builds a model (built in, or from a plugin), solves a box
 * of cells of its state space by simple cell mapping (SCM; one region, or
 * several solved concurrently and joined into one cluster, C-SCM), reads
 * any view of a cluster database (.cmdb) that `cellmap solve --db` or
 * `cellmap explore` wrote, and renders a result as a basin figure in PNG.
 * Link with `pkg-config --libs cellmap` (libcellmap.so, or libcellmap.a
 * with `--static`).
 *
 * The contract, for every function here:
 * - Status. A function that can fail returns a cm_status: CM_OK (0) or a
 *   positive code (cellmap/status.h; cm_strerror describes it, cm_status_name
 *   gives its symbol, e.g. "CM_EINVAL"). When msg is not
 *   NULL it receives a one-line reason that names the problem and its fix,
 *   NUL-terminated within msg_size bytes (256 is always enough to be
 *   useful). On failure no output object is made (*out is NULL) and no file
 *   is left half-written.
 * - Ownership. Objects are opaque. What cm_X_new / cm_X_open / cm_solve /
 *   cm_db_read give, the caller releases with the matching cm_X_free /
 *   cm_db_close (NULL is accepted and ignored). Arrays are the caller's:
 *   functions fill buffers of the documented length and never keep them.
 *   A system keeps a pointer to its model set, a result to nothing: free a
 *   set after the systems made from it.
 * - Threads. Different objects may be used from different threads at the
 *   same time; one object is not to be used from two threads at once,
 *   except cm_system_step, which is pure and may run on many threads at
 *   once. cm_solve and cm_db_read use OpenMP threads of their own (options
 *   say how many); their results do not depend on the thread count.
 * - Units. States are in the model's own coordinates (`cellmap models`
 *   names them); a grid's box is [lo, hi) per dimension cut into cells[d]
 *   equal cells; arrays over cells run with dimension 0 fastest (C order of
 *   an array shaped cells[dim-1] x ... x cells[0]). Times are seconds.
 * - Labels. A cell's label is its periodic group's id 1..groups (a cell
 *   cycle of cell mapping, or a sticking zone of a friction model), 0 for
 *   the sink (its sequence leaves the solved cells or has no image), or
 *   CM_LABEL_NONE for a cell of a view that no region of a database covers.
 *   Its step number counts the map's steps to its group's periodic cells
 *   (0 on them). Its attractor label is the system's attractor its group's
 *   true orbit reaches, and for a sink cell the attractor the true orbit
 *   from the cell its sequence leaves into comes back to
 *   (cm_result_attractor_labels; docs/engine.md, "Attractors" and "Orbits
 *   that leave the computed cells").
 * - Versions. CELLMAP_VERSION_* are this header's; cm_version() the
 *   library's. The same major version keeps source and binary
 *   compatibility (the library's SONAME is libcellmap.so.MAJOR) for the
 *   stable section; the experimental section at the end (defined only
 *   when CELLMAP_EXPERIMENTAL is defined before this header is included,
 *   as zstd's static-linking-only section) may change in any release.
 * - OpenMP. The library runs its loops on OpenMP threads of the process's
 *   one OpenMP runtime (libgomp on Debian): a program that also uses
 *   OpenMP shares it, and a call's `threads` option sets the call's team
 *   only.
 * - fork(). Fork only while no call of the library runs in another thread
 *   (OpenMP's threads are not copied); a child may use objects the parent
 *   made, but not an open cm_db, cm_session or database file the parent
 *   also goes on using: SQLite connections must not cross a fork.
 */
#ifndef CM_CELLMAP_H
#define CM_CELLMAP_H

#include <stddef.h>
#include <stdint.h>

#include "cellmap/status.h"

/* The most state dimensions a model has (as cellmap/lattice.h says). */
#define CM_MAX_DIM 6

#ifdef __cplusplus
extern "C" {
#endif

#define CELLMAP_VERSION_MAJOR 0
#define CELLMAP_VERSION_MINOR 3
#define CELLMAP_VERSION_PATCH 0
/* MAJOR * 10000 + MINOR * 100 + PATCH */
#define CELLMAP_VERSION_NUMBER                                                                     \
    (CELLMAP_VERSION_MAJOR * 10000 + CELLMAP_VERSION_MINOR * 100 + CELLMAP_VERSION_PATCH)

/* The library's version as "MAJOR.MINOR.PATCH", and as a number. */
const char *cm_version(void);
int cm_version_number(void);

/* The description of a status code ("out of memory", ...), and its
 * symbolic name ("CM_ENOMEM"); static strings, never NULL. */
const char *cm_strerror(cm_status st);
const char *cm_status_name(cm_status st);

/* ---- models -------------------------------------------------------------- */

/* The models a program can build: cellmap's own and those of the plugins
 * it loads (cellmap/plugin.h). */
typedef struct cm_models cm_models;

cm_status cm_models_new(cm_models **out, char *msg, size_t msg_size);
/* Loads the plugin at path (a shared object exporting cellmap_plugin());
 * refused, with both versions named, when built for another plugin ABI. */
cm_status cm_models_load(cm_models *set, const char *path, char *msg, size_t msg_size);
/* How many models the set has, and the name of model i (NULL past the end). */
size_t cm_models_count(const cm_models *set);
const char *cm_models_name(const cm_models *set, size_t i);
void cm_models_free(cm_models *set);

/* A model built with its parameters: a dynamical system. */
typedef struct cm_system cm_system;

/* Model `name` of set (NULL: cellmap's own models only) with parameters
 * "k=v,k=v" over its defaults (params NULL or "": the defaults). */
cm_status cm_system_new(const cm_models *set, const char *name, const char *params,
                        cm_system **out, char *msg, size_t msg_size);
int cm_system_dim(const cm_system *s);
const char *cm_system_name(const cm_system *s);
/* The name of state coordinate d (e.g. "x", "v"). */
const char *cm_system_coord(const cm_system *s, int d);
/* The model's default region into lo[dim], hi[dim]; CM_ENOTFOUND if it has none. */
cm_status cm_system_region(const cm_system *s, double *lo, double *hi);
/* One step of the map from x into y (dim values each): CM_STEP_OK, or
 * CM_STEP_NO_IMAGE (the sink). Pure and thread-safe. */
int cm_system_step(const cm_system *s, const double *x, double *y);
void cm_system_free(cm_system *s);

/* ---- solving ------------------------------------------------------------- */

/* A box of state space cut into cells: [lo[d], hi[d]) in cells[d] cells. */
typedef struct cm_grid {
    int dim;
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    int64_t cells[CM_MAX_DIM];
} cm_grid;

/* Called on the calling thread with the fraction of the work done (0..1),
 * at least once, last with 1 when the work is done; a nonzero return
 * cancels: the call then returns CM_ECANCELED. */
typedef int (*cm_solve_progress_fn)(void *user, double fraction);

typedef struct cm_solve_options {
    int threads;   /* OpenMP threads; 0: all cores */
    int max_steps; /* re-step while the image stays in its cell, up to this many steps
                      (0 and 1: one step; useful for flows and slow maps) */
    /* regions per dimension, solved concurrently and joined into one
     * cluster (C-SCM); all 0: one region. The labels are the same either
     * way, up to the numbering of the groups. */
    int64_t split[CM_MAX_DIM];
    cm_solve_progress_fn progress; /* optional */
    void *user;
} cm_solve_options;

/* Labels, step numbers and groups of a grid's cells. */
typedef struct cm_result cm_result;

/* Solves grid for system s (opt NULL: the defaults). */
cm_status cm_solve(const cm_system *s, const cm_grid *grid, const cm_solve_options *opt,
                   cm_result **out, char *msg, size_t msg_size);

#define CM_LABEL_NONE UINT32_C(0xFFFFFFFF)

/* The result's grid (of a database view: the lattice's cells it covers). */
void cm_result_grid(const cm_result *r, cm_grid *grid);
/* Its number of cells, the product of grid.cells. */
uint64_t cm_result_cells(const cm_result *r);
/* Every cell's label, and step number, into arrays of cm_result_cells entries. */
void cm_result_labels(const cm_result *r, uint32_t *labels);
void cm_result_steps(const cm_result *r, uint32_t *steps);
/* The number of groups: labels run 1..cm_result_groups (a database view
 * may hold no cell of some of them). */
uint32_t cm_result_groups(const cm_result *r);

/* A periodic group, as far as the result's cells show it. */
typedef struct cm_group_summary {
    uint32_t id;
    int kind;              /* 0: attractor; 1: sticking zone (rest states held by friction) */
    uint32_t period;       /* its periodic cells among the result's */
    uint64_t basin_cells;  /* cells labelled id, periodic ones included */
    double centre[CM_MAX_DIM]; /* mean centre of its periodic cells */
} cm_group_summary;

/* Group id (1..cm_result_groups) into *out; CM_ENOTFOUND beyond. */
cm_status cm_result_group(const cm_result *r, uint32_t id, cm_group_summary *out);
/* Cells labelled 0 (the sink). */
uint64_t cm_result_sink_cells(const cm_result *r);
/* The system's attractors behind the groups (found by their true orbits,
 * as `cellmap solve` finds them, with its default options; a database's
 * are those it stores, else found from its cells): periodic, aperiodic
 * (chaotic or quasi-periodic: its footprint is the cells its orbit visits)
 * or a sticking zone. */
typedef struct cm_attractor_summary {
    uint32_t id;
    int kind;        /* 0: periodic; 1: aperiodic; 2: sticking zone */
    uint32_t period; /* its true period; 0 when aperiodic */
    uint64_t basin_cells; /* the basins of its groups (the whole cluster's, for a database) */
    uint32_t groups;      /* cell groups that are this attractor */
    double centre[CM_MAX_DIM], lo[CM_MAX_DIM], hi[CM_MAX_DIM]; /* mean and bounds of its
                                  cycle's states, or of its footprint's cell centres */
    int64_t anchor[CM_MAX_DIM]; /* the smallest cell of its footprint: its identity */
    uint64_t footprint_cells;
} cm_attractor_summary;

/* How many attractors: ids run 1..cm_result_attractors. */
uint32_t cm_result_attractors(const cm_result *r);
/* Attractor id into *out; CM_ENOTFOUND beyond. */
cm_status cm_result_attractor(const cm_result *r, uint32_t id, cm_attractor_summary *out);
/* Every cell's attractor label into an array of cm_result_cells entries:
 * the attractor's id; 0 when it diverges (its group's true orbit does, or
 * its sequence has no image, or leaves the solved cells on an orbit that
 * leaves the world); -2 outside (it leaves the solved cells and its orbit
 * does not come back within the budget, 100 steps, or its group's orbit
 * was undecided); -1 for a cell no region covers. */
void cm_result_attractor_labels(const cm_result *r, int32_t *labels);

/* The basin figure (basins by the system's attractors, their footprints,
 * axes, legend, title; diverged cells red, outside or undecided ones
 * grey) as a PNG of width x height pixels (0, 0: 1000 on the longer
 * side), written to a temporary file and renamed to path. Loads OSMesa on
 * first use. */
cm_status cm_result_png(const cm_result *r, const char *path, int width, int height, char *msg,
                        size_t msg_size);
void cm_result_free(cm_result *r);

/* ---- cluster databases (.cmdb) ------------------------------------------- */

typedef struct cm_db cm_db;

/* Opens a database read-only; a model from a plugin is loaded from the
 * path the file records (and refused if it changed). Regions are read
 * back on demand and at most 256 MiB of them stay in memory (a larger
 * cluster is paged: cm_db_read of a view reads only the regions it
 * meets). A file being written by another process may be read: a reader
 * sees one snapshot, the commits up to its open (docs/format.md). */
cm_status cm_db_open(const char *path, cm_db **out, char *msg, size_t msg_size);
/* The file's model: name, parameters as a JSON object. */
const char *cm_db_model(const cm_db *db);
const char *cm_db_params(const cm_db *db);
/* The smallest grid of the lattice that holds every region. */
void cm_db_grid(const cm_db *db, cm_grid *grid);
/* The cells of the lattice that meet the box lo..hi (NULL, NULL: the whole
 * cluster), resolved: labels and steps exactly as `cellmap export` gives
 * them. Reads only the regions the box meets. */
cm_status cm_db_read(cm_db *db, const double *lo, const double *hi, cm_result **out, char *msg,
                     size_t msg_size);
void cm_db_close(cm_db *db);

#ifdef CELLMAP_EXPERIMENTAL
/* ==== experimental: projects, sessions, figures, systems from functions,
 *      analysis drivers ====
 * What the command `cellmap` does over whole databases and its analysis
 * commands, for C (and the Python module): the same drivers (lib/), so
 * the same files, images and arrays. May change in any release. */

/* ---- systems given as a function ---- */

/* y = f(x) for a state x of dim coordinates; 0: an image, > 0: no image
 * (the cell goes to the sink), < 0: abort the computation. Called from the
 * threads of the calls that step the system: pure, or serialised by the
 * caller (a Python function through ctypes holds the interpreter's lock). */
typedef int (*cm_step_fn)(void *user, const double *x, double *y);

/* A system whose map is fn (user passed along), named name (1..63
 * characters, for figures and files), of dim coordinates (1..CM_MAX_DIM).
 * A database made of it records the name only: it is read back with
 * cm_db_open (labels, steps, stored attractors), not resumed or explored. */
cm_status cm_system_from_function(const char *name, int dim, cm_step_fn fn, void *user,
                                  cm_system **out, char *msg, size_t msg_size);

/* ---- figures ---- */

/* Layers of a figure (as `cellmap render --layers` names them). */
enum {
    CM_FIGURE_BASIN = 1 << 0,
    CM_FIGURE_STEPS = 1 << 1,
    CM_FIGURE_ATTRACTORS = 1 << 2,
    CM_FIGURE_OVERLAYS = 1 << 3,
    CM_FIGURE_AXES = 1 << 4,
    CM_FIGURE_LEGEND = 1 << 5,
    CM_FIGURE_TITLE = 1 << 6
};

/* What a figure draws and where it goes: as `cellmap render`'s options. */
typedef struct cm_figure_options {
    const char *png;     /* PNG file, or NULL */
    const char *svg;     /* the same figure as SVG, or NULL */
    int width, height;   /* pixels; 0, 0: one pixel per cell (at most 4096), 1000 with text */
    unsigned layers;     /* CM_FIGURE_*; 0: every layer but steps */
    int indexed;         /* 1: an indexed PNG of one pixel per cell (its value: the colour class) */
    int by_groups;       /* 1: cell mapping's groups; 0: the system's attractors */
    const char *palette; /* "cellmap" (NULL), "tol", "okabe-ito", "tab20" or a file of
                            #rrggbb lines */
    const char *labels;  /* a file of legend names ("ID TEXT" lines), or NULL */
    uint64_t min_basin;  /* groups of fewer cells drawn as "other"; 0: 2 with a legend, else 1 */
    int legend;          /* groups the legend lists; 0: 12 */
    const char *title;   /* the title (with CM_FIGURE_TITLE); NULL: the model and its
                            parameters; wrapped */
    double aspect;       /* a state unit along y drawn `aspect` times as long as one along
                            x (1: equal); -1: the plot fills its room; 0: 1 for models whose
                            axes share a unit (cm_model.equal_axes), else -1 */
    double font_size;    /* text in points (1..96; font_size * dpi / 72 pixels); 0: from the
                            image's size */
    double dpi;          /* pixels per inch (36..2400): the PNG's pHYs, the SVG's size in
                            points, the font's pixels; 0: none written (96 for the font) */
    const char *pdf;     /* the same figure as PDF (the SVG drawn by librsvg and cairo,
                            loaded when needed), or NULL */
} cm_figure_options;

/* The figure of a result (cm_solve, cm_db_read, cm_session_read), through
 * the pipeline `cellmap solve --png` and `render` use. */
cm_status cm_result_figure(const cm_result *r, const cm_figure_options *o, char *msg,
                           size_t msg_size);

/* ---- projects: databases made and grown ---- */

/* The processes mpirun started (MPI ranks), for solves shared among them
 * (cm_db_options.ranks): rank 0 runs the solve and writes the file, the
 * others solve regions for it. Every rank opens them, makes the same calls
 * with the same model, parameters, grid and plan (each may use its own
 * threads), and closes them. Outside mpirun they are one rank (rank 0)
 * and MPI is not loaded; under mpirun, cm_ranks_open loads
 * libcellmap-mpi.so.0 from libcellmap's own directory (built where MPI is
 * found: CM_ENOTFOUND without it) and starts MPI, unless the program
 * started it (with MPI_THREAD_SERIALIZED or above), which then also ends
 * it. Every rank must run the same libcellmap (a hash of its file), or
 * every rank fails with rank 0 naming the one that differs. One per
 * process, used from one thread at a time. */
typedef struct cm_ranks cm_ranks;
cm_status cm_ranks_open(cm_ranks **out, char *msg, size_t msg_size);
int cm_ranks_rank(const cm_ranks *r);
int cm_ranks_size(const cm_ranks *r);
/* Ends them (and MPI, if cm_ranks_open started it); NULL: nothing. */
void cm_ranks_close(cm_ranks *r);

/* How a database is solved: as `cellmap solve --db` with --split, --extend,
 * --escape-below, --max-steps, --threads and --mem. */
typedef struct cm_db_options {
    int threads;          /* 0: all cores */
    int max_steps;        /* 0: 1 */
    int64_t split[CM_MAX_DIM]; /* regions per dimension; all 0: one region */
    int extend;           /* adaptive extension steps (thesis 4.6.4), 0..1000 */
    double escape_below;  /* stop extending below this escaping fraction (0: never) */
    uint64_t mem;         /* bytes of cell arrays held in memory; 0: an eighth of the
                             machine's memory, 16..128 MiB */
    const char *command;  /* the provenance the file records; NULL: "libcellmap" */
    cm_solve_progress_fn progress; /* optional: fraction of the grid's cells; nonzero cancels */
    void *user;
    /* optional (cm_db_create, cm_db_resume): the regions (split, extend)
     * shared among these ranks; on ranks other than 0 the call returns
     * once rank 0's solve has ended, with its status, and writes nothing
     * (progress is rank 0's). The file is the same bytes for any number
     * of ranks. More ranks than regions, or ranks asked for different
     * solves: every rank fails, rank 0 says why. cm_db_add_box and
     * cm_db_extend refuse more than one rank (CM_EINVAL). */
    cm_ranks *ranks;
} cm_db_options;

/* Solves grid for model `name` of set (NULL: the built-in models) with
 * parameters params ("k=v,..."; NULL: the defaults) into a new database at
 * path (replacing an older cellmap database there only once complete;
 * never another file), with the system's attractors stored. Cancelled or
 * failed, every join done so far is committed: cm_db_resume completes it
 * (a new file that replaced nothing yet leaves the older one as it was). */
cm_status cm_db_create(const cm_models *set, const char *name, const char *params,
                       const cm_grid *grid, const char *path, const cm_db_options *o, char *msg,
                       size_t msg_size);

/* Completes a database cm_db_create (or `cellmap solve --db`) began, with
 * the same model, parameters, grid and plan (split, extend, escape_below,
 * max_steps); anything else is refused and the file left as it is. */
cm_status cm_db_resume(const cm_models *set, const char *name, const char *params,
                       const cm_grid *grid, const char *path, const cm_db_options *o, char *msg,
                       size_t msg_size);

/* The cells of the database's lattice whose centres lie in lo..hi (NULL,
 * NULL: every cell) as .npy arrays (int32, C order, axis k = dimension k)
 * with their JSON sidecars, as `cellmap export --labels --steps [--window]`
 * writes them: labels by the system's attractors (by_groups: by groups),
 * steps; either path may be NULL. */
cm_status cm_db_export(const char *path, const double *lo, const double *hi, const char *labels,
                       const char *steps, int by_groups, char *msg, size_t msg_size);

/* The cells of the rectangle lo..hi (every dimension of the file's
 * lattice; a cell is in when the rectangle covers it by the lattice's
 * rule, as a session's view) that the database at path lacks, solved as
 * new regions, joined exactly and committed one join at a time;
 * *new_cells (may be NULL): how many. The file keeps its model, lattice
 * and max steps (o->max_steps, when given, must be the file's); o (may be
 * NULL) gives threads, mem and the provenance. At most 2^28 new cells per
 * call (with o->mem: what it holds, 12 bytes a cell). */
cm_status cm_db_add_box(const char *path, const double *lo, const double *hi,
                        const cm_db_options *o, uint64_t *new_cells, char *msg, size_t msg_size);

/* Adaptive extension (thesis 4.6.4) of the database at path: up to steps
 * (1..1000) times, the tile of lo..hi's size (its cells per dimension)
 * next to the cluster where the most sequences escape is computed and
 * joined, as `cellmap solve --extend` does from its region; *done (may be
 * NULL): the steps done (fewer when nothing escapes any more). o as for
 * cm_db_add_box. */
cm_status cm_db_extend(const char *path, const double *lo, const double *hi, int steps,
                       const cm_db_options *o, int *done, char *msg, size_t msg_size);

/* ---- sessions: a view moved over a growing database ---- */

typedef struct cm_session cm_session;

/* How a session's database is made when it does not exist (as `cellmap
 * explore`'s options); an existing file keeps its own. */
typedef struct cm_session_options {
    const char *model;             /* a new file's model; NULL: the file must exist */
    const char *params;            /* its parameters ("k=v,..."), or NULL */
    const cm_models *set;          /* where the model comes from; NULL: built in */
    double cell_size[CM_MAX_DIM];  /* a new file's cells, one width per dimension */
    double origin[CM_MAX_DIM];     /* its lattice's origin (default 0) */
    const char *depth;             /* "LO:HI,..." of dimensions 3.. of a new file's model */
    int max_steps, threads;        /* 0: 1 for a new file; 0: all cores */
    uint64_t mem;                  /* bytes of cell arrays in memory; 0: an eighth of the
                                      machine's memory, 16..128 MiB */
    const char *command;           /* provenance; NULL: "libcellmap" */
} cm_session_options;

/* Opens (or creates) a session's database at path. */
cm_status cm_session_open(const char *path, const cm_session_options *o, cm_session **out,
                          char *msg, size_t msg_size);

/* Moves the view to lo..hi (dimensions 0 and 1) and computes exactly the
 * cells it uncovers, each join committed; *new_cells (may be NULL): how
 * many. A session without a view (a new file) starts with this. */
cm_status cm_session_view(cm_session *s, const double *lo, const double *hi,
                          uint64_t *new_cells, char *msg, size_t msg_size);

/* The view now (dimensions 0 and 1); CM_ENOTFOUND before the first. */
cm_status cm_session_bounds(const cm_session *s, double *lo, double *hi);

/* The view moved by `by` in dimension d (state units), or zoomed by
 * factor about its centre (2: twice as close), as `pan` and `zoom` do. */
cm_status cm_session_pan(cm_session *s, int d, double by, uint64_t *new_cells, char *msg,
                         size_t msg_size);
cm_status cm_session_zoom(cm_session *s, double factor, uint64_t *new_cells, char *msg,
                          size_t msg_size);

/* `extend auto steps`: up to steps (1..1000) times, the tile of the view's
 * size where the most sequences escape; *done (may be NULL): steps done. */
cm_status cm_session_extend(cm_session *s, int steps, int *done, char *msg, size_t msg_size);

/* The view's cells (the slice shown) as a result: labels, steps, groups
 * and the system's attractors found over the whole cluster. */
cm_status cm_session_read(cm_session *s, cm_result **out, char *msg, size_t msg_size);

/* What a session knows of the cell that holds a state. */
typedef struct cm_cell_info {
    int64_t cell[CM_MAX_DIM];  /* its index in the file's lattice */
    double centre[CM_MAX_DIM]; /* its centre */
    uint32_t label;            /* 0 the sink, k group k, CM_LABEL_NONE not computed */
    uint32_t step;             /* steps to its group's cycle (cm_result_steps) */
    int32_t attractor;         /* the system's attractor, as cm_result_attractor_labels */
} cm_cell_info;

/* The cell of the file's lattice that holds state x (one coordinate per
 * dimension of the model), computed or not: its group, step and attractor
 * (the attractors found over the whole cluster, as cm_session_read does;
 * each query finds them again). Nothing is computed or moved. CM_EINVAL:
 * x is not finite or outside the lattice's world. */
cm_status cm_session_query(cm_session *s, const double *x, cm_cell_info *out, char *msg,
                           size_t msg_size);

/* The view's figure, as `render` in a session draws it (the same bytes). */
cm_status cm_session_figure(cm_session *s, const cm_figure_options *o, char *msg,
                            size_t msg_size);

/* Saves the view and the attractors and closes the database (NULL: nothing). */
cm_status cm_session_close(cm_session *s, char *msg, size_t msg_size);

/* ---- analysis drivers ----
 * The commands `stability`, `partition`, `amplitude`, `horseshoe`,
 * `escape`, `equilibria`, `periodic`, `simulate`, `bifurcation`, `lyapunov`, `sweep`
 * and `continue`
 * as calls: the same computation and the same files (CSV tables and PNG
 * figures, byte for byte) as the command with the same settings. Each
 * takes the model and outputs (cm_analysis) and its own settings (an
 * options struct whose cm_*_defaults() are the command's defaults);
 * nothing is printed. Outputs are written whole or not at all (a
 * temporary file renamed into place). CM_EINVAL: the request's problem,
 * named in msg. The threads are OpenMP's (see above). */

/* One parameter's values: n cells evenly over lo..hi, each value a
 * cell's centre (as the commands' NAME=LO:HI:N). */
typedef struct cm_axis {
    const char *name; /* a parameter of the model (a driver's own axis: its name) */
    double lo, hi;    /* lo < hi */
    int n;            /* 1.. (each driver says its limit) */
} cm_axis;

/* The model and the outputs of an analysis. */
typedef struct cm_analysis {
    const cm_models *set; /* where the model comes from; NULL: built in */
    const char *model;    /* NULL: the driver's own model (the command's default) */
    const char *params;   /* "k=v,..."; NULL: the model's defaults */
    const char *csv;      /* the table as CSV ("-": standard output), or NULL */
    const char *png;      /* the figure as PNG, or NULL */
    int width, height;    /* the figure's pixels; 0, 0: the command's size */
    int threads;          /* 0: all cores */
} cm_analysis;

/* microchaos-pd's analytic charts (thesis 4.5, C.4): the stability
 * domain, fixed points and control error over P (NULL: 1.0025 alpha^2 ..
 * 1.2 P_max, 400 values) and the fewest fixed points over alpha (NULL:
 * 0.05..3, 300 values); axes of 2..100000 values. */
cm_status cm_analysis_stability(const cm_analysis *a, const cm_axis *P, const cm_axis *alpha, char *msg,
                       size_t msg_size);

/* microchaos-delay's Markov partition of (0, 1) and transition matrix
 * (thesis 4.4, Fig. 4.11). */
cm_status cm_analysis_partition(const cm_analysis *a, char *msg, size_t msg_size);

/* friction-oscillator's amplitude-frequency diagram (thesis 2.2) over
 * Omega (omega->name ignored; 0 < lo, 1..100000 values), against
 * simulation of `periods` (50..100000; 0: 400) periods; the figure's y
 * axis up to ymax (0: 5). */
cm_status cm_analysis_amplitude(const cm_analysis *a, const cm_axis *omega, int periods, double ymax,
                       char *msg, size_t msg_size);

typedef struct cm_horseshoe_options {
    int64_t m0, m1;       /* switching lines m0..m1 (1 <= m0, m1 - m0 <= 1000); 0, 0: 1..m_max */
    int periods;          /* periodic points of this period, 1..20 */
    const cm_axis *sweep; /* P over 1..10000 values, or NULL: the model's P */
    int crisis;           /* 1: the crisis chart of the sweep */
} cm_horseshoe_options;
cm_horseshoe_options cm_horseshoe_defaults(void); /* lines 1..m_max, period 12 */

/* microchaos-pd's horseshoes at its switching lines (thesis 4.5.3). */
cm_status cm_analysis_horseshoe(const cm_analysis *a, const cm_horseshoe_options *o, char *msg,
                       size_t msg_size);

typedef struct cm_escape_options {
    double I0;            /* |I0| (0 < I0 < 1e6) sets c at each point; 0: the model's c */
    const cm_axis *sweep; /* a, b or I0 over 1..10000 values, or NULL: one point */
    long cells;           /* cells of the cell-mapping estimate (0: none), up to 10^8 */
    long ensemble;        /* states of the ensemble's estimate (0: none), up to 10^9 */
} cm_escape_options;
cm_escape_options cm_escape_defaults(void); /* 100000 cells, an ensemble of 10^6 */

/* microchaos-1d-friction's transient chaos (thesis 4.3): the repeller,
 * its escape rate and mean escape number, exact and estimated. */
cm_status cm_analysis_escape(const cm_analysis *a, const cm_escape_options *o, char *msg, size_t msg_size);

/* A start and, with a name, the branch through it in one parameter (the
 * commands' --from, --branch NAME=LO:HI, --direction, --ds-max and
 * --max-points). */
typedef struct cm_branch {
    const double *from; /* the start */
    int n_from;         /* its coordinates */
    const char *name;   /* NULL: the start's solution only; else the parameter */
    double lo, hi;      /* the branch's range, holding the model's value of it */
    int direction;      /* +1 or -1: that way only; 0: both */
    double ds_max;      /* the longest arclength step; 0: (hi - lo) / 50 */
    int max_points;     /* points each way, 10..1000000 (the defaults: 10000) */
} cm_branch;

typedef struct cm_equilibria_options {
    cm_branch b;          /* from: in the flow's coordinates */
    const cm_axis *curve; /* NULL, or the Hopf points of the branch at each of these
                             values (1..2000) of a second parameter */
} cm_equilibria_options;
cm_equilibria_options cm_equilibria_defaults(void); /* both ways, 10000 points */

/* The equilibria of a flow model (default chip-4d; `cellmap
 * equilibria`): Newton from o->from with the eigenvalues; the branch in
 * o->branch with its folds and Hopf points; Hopf points over o->curve.
 * The table only (a->png must be NULL). CM_ENOTFOUND: Newton did not
 * converge. */
cm_status cm_analysis_equilibria(const cm_analysis *a, const cm_equilibria_options *o, char *msg,
                                 size_t msg_size);

typedef struct cm_periodic_options {
    cm_branch b; /* from: in the map's coordinates; a cascade needs a direction */
    int settle;  /* iterates of the map before Newton, 0..1e7 */
    int period;  /* 1..4096 */
    int cascade; /* period doublings to follow, 0..12 */
} cm_periodic_options;
cm_periodic_options cm_periodic_defaults(void); /* period 1, both ways, 10000 points */

/* Periodic orbits of a model's map (default chip-4d; `cellmap
 * periodic`): Newton on P^k from o->from (after o->settle iterates) with
 * the multipliers; the branch in o->branch with its folds, period
 * doublings and Neimark-Sacker points; a cascade of doublings. A flow's
 * tolerances become 1e-12 unless a->params sets them. The table only
 * (a->png must be NULL). CM_ENOTFOUND: Newton did not converge. */
cm_status cm_analysis_periodic(const cm_analysis *a, const cm_periodic_options *o, char *msg,
                               size_t msg_size);

typedef struct cm_exponents_options {
    double start[CM_MAX_DIM]; /* the flow's coordinates (of_map: the map's) */
    int n_from;               /* 0: the centre of the model's example region */
    int of_map;               /* nonzero: the map's spectrum (a map model's always) */
    int count;                /* exponents, 0: all */
    double time, transient, renorm; /* flows (and chip-bue: time, transient) */
    long iterations, skip;          /* maps */
    int samples, gs;          /* chip-bue: Farmer's map */
    int sync;                 /* chip-bue: the synchronisation estimate instead */
    double q_max;             /* with sync: q in 0..q_max */
} cm_exponents_options;
/* flows 100 after 10, renormalised every 0.1; maps 10000 after 100;
 * chip-bue 20 samples a delay, Gram-Schmidt every 10 steps, q up to 20 */
cm_exponents_options cm_exponents_defaults(void);

typedef struct cm_exponents {
    int count;
    double lambda[CM_MAX_DIM]; /* decreasing: per unit time (flows, chip-bue), per iterate (maps) */
    double kaplan_yorke;       /* NAN when more exponents are needed */
    double mean_flight;        /* a flow's map: the mean time between iterates; else NAN */
} cm_exponents;

/* The Lyapunov spectrum of one orbit (default model chip-4d; `cellmap
 * exponents`): a flow's by its variational equations, a map's by the QR
 * of its Jacobian, chip-bue's by Farmer's discretised map or the
 * synchronisation estimate. out (may be NULL) gets the result; a->csv the
 * running estimates, a->png their chart. CM_EMODEL: the orbit was lost. */
cm_status cm_analysis_exponents(const cm_analysis *a, const cm_exponents_options *o,
                                cm_exponents *out, char *msg, size_t msg_size);

typedef struct cm_series_options {
    double start[2 * CM_MAX_DIM]; /* the flow's coordinates */
    int n_from;                   /* 0: the centre of the example region (chip-bue: its start-up) */
    double time, skip, dt;        /* followed to time, kept after skip, every dt */
    const char *of;               /* the coordinate drawn and transformed; NULL: the first */
    double time_unit;             /* seconds per unit of time (0: no Hz) */
    double fmax;                  /* the spectrum drawn up to this (Hz given time_unit); 0: all */
    const char *spectrum_csv;     /* frequency[,frequency_hz],power, or NULL */
    int returns;                  /* nonzero: the figure adds the return map at the section */
} cm_series_options;
cm_series_options cm_series_defaults(void); /* 100 time units every 0.01, none skipped */

/* The time series of a flow model or chip-bue (`cellmap simulate --model
 * FLOW`; there is no default model: a->model must name one) and the power
 * spectrum of one coordinate (FFTW): a->csv the samples, a->png the
 * history over the spectrum. */
cm_status cm_analysis_series(const cm_analysis *a, const cm_series_options *o, char *msg,
                             size_t msg_size);

typedef struct cm_embedding_options {
    const char *input;            /* a CSV file with a header (a column t gives the times), or
                                     NULL: the orbit of a->model (a flow or chip-bue; chip-4d) */
    const char *of;               /* the column or coordinate; NULL: the file's first but t,
                                     the model's first */
    double start[2 * CM_MAX_DIM]; /* the model's start */
    int n_from;                   /* 0: the centre of the example region */
    double time, transient, dt;   /* the model's run: to time, kept after transient, every dt */
    int values;                   /* +1: successive maxima, -1: minima, 0: every value */
    int dim_lo, dim_hi;           /* the curves' embedding dimensions; 0: from the false
                                     neighbours (the least with < 1 %, and 2 more) */
    int lag, steps, fnn_dim, theiler;
    double radius[8];             /* the neighbourhoods, fractions of the series' range */
    int n_radius;
    int fit_lo, fit_hi;           /* the steps fitted; fit_hi 0: each curve to half its rise */
    double time_unit;             /* seconds per unit of time (0: no 1/s) */
} cm_embedding_options;
/* maxima; lag 1, 40 steps, false neighbours up to 14, radii 0.005, 0.01,
 * 0.02; the model's run 100 time units every 0.01 */
cm_embedding_options cm_embedding_defaults(void);

typedef struct cm_embedding {
    size_t n;                 /* the values analysed */
    double interval;          /* the mean time between them; NAN when unknown */
    int embedding_dim;        /* the least with < 1 % false neighbours; 0: none */
    int fnn_dim;
    double false_neighbours[64];
    double lambda, spread;    /* per value: the curves' mean slope, their deviation */
    double lambda_per_time;   /* lambda / interval */
} cm_embedding;

/* The largest Lyapunov exponent and the embedding dimension of one series
 * (`cellmap exponents --series`, thesis Figs. 3.12, 3.15): false nearest
 * neighbours and Kantz's divergence curves of a model's coordinate or a
 * file's column. out (may be NULL) gets the result; a->csv the curves,
 * a->png the delay projection over them. */
cm_status cm_analysis_embedding(const cm_analysis *a, const cm_embedding_options *o,
                                cm_embedding *out, char *msg, size_t msg_size);

typedef struct cm_measure_options {
    const char *file;       /* the .cmdb file measured */
    const char *window;     /* "X0:X1[,Y0:Y1...]" in state units; NULL: every cell */
    int box[8];             /* basin entropy's box sizes in cells */
    int n_box;              /* 0: no basin entropy */
    int eps_lo, eps_hi;     /* uncertain fractions for eps = lo, 2 lo, ... <= hi; hi 0: none */
    int wada_radius;        /* the Wada test for r = 1 .. radius (1..16); 0: none */
    int wada_required;      /* nonzero: fewer than 3 basins is an error, else the test is skipped */
    const char *to;         /* a second file on the same lattice: tipping probabilities, or NULL */
    uint64_t mem;           /* the cluster's and the labels' budget in bytes */
    uint64_t samples;       /* random states of the window followed by their true orbits to
                               their attractors (at most 10^8; 0: none) */
    uint64_t seed;          /* their stream: the same states for the same seed */
    int threads;            /* OpenMP threads following them; 0: the OpenMP default */
    double orbit_eps_lo, orbit_eps_hi; /* with samples: uncertain fractions by true orbits for
                                          eps = lo, 2 lo, ... <= hi cells; hi 0: none */
} cm_measure_options;
/* boxes 3, 5, 7, 9; eps 1 .. 16; Wada to r = 5; 256 MiB; no samples, seed 1 */
cm_measure_options cm_measure_defaults(void);

typedef struct cm_measures {
    uint64_t cells, computed;  /* the window's cells, those computed */
    double sb, sbb;            /* means over the box sizes; NAN without */
    double alpha, alpha_r2;    /* the uncertainty exponent and its fit's R^2; NAN without */
    int wada_basins;           /* 0: no Wada test */
    double wada_fraction;      /* boundary cells seeing every basin within wada_radius */
    uint64_t sampled;          /* samples in computed cells (0: none) */
    uint64_t sampled_as_labelled; /* of them, those whose true orbit ends where their cell's
                                     label says */
    int samples_agree;         /* nonzero: every basin's cell share lies within the
                                  interval of its sampled share */
    double orbit_alpha, orbit_alpha_r2; /* the uncertainty exponent by true orbits; NAN without */
} cm_measures;

/* A file's basins measured (`cellmap measure`): a->csv gets every value as
 * rows measure,scale,value (share, sampled, sb, sbb, uncertain, orbit_uncertain,
 * wada, tipping),
 * a->png the figure of a 2-D window (the entropy map of the first box size
 * over the uncertain fractions, log-log), out (may be NULL) the summary;
 * a->model is not used. */
cm_status cm_analysis_measure(const cm_analysis *a, const cm_measure_options *o, cm_measures *out,
                              char *msg, size_t msg_size);

typedef struct cm_simulate_options {
    double x, v;     /* the start */
    double t0;       /* its time; NaN: the Poincare section's phase phi/Omega */
    int periods;     /* 1..100000 */
    int skip;        /* the first periods not recorded, 0..periods - 1 */
} cm_simulate_options;
cm_simulate_options cm_simulate_defaults(void); /* from (0, 0), 20 periods */

/* A trajectory of friction-oscillator through its stick and slip phases
 * (thesis Ch. 2): its events and samples, time history and phase portrait. */
cm_status cm_analysis_simulate(const cm_analysis *a, const cm_simulate_options *o, char *msg,
                      size_t msg_size);

typedef struct cm_bifurcation_options {
    cm_axis sweep;        /* the parameter swept (values x runs x record <= 10^7) */
    int runs;             /* random starts per value, 1..1000 */
    int transient;        /* periods dropped, 0..10^6 */
    int record;           /* periods recorded, 1..10000 */
    long long seed;       /* of the starts, >= 0 */
    const char *runs_csv; /* one line per run as CSV, or NULL */
} cm_bifurcation_options;
cm_bifurcation_options cm_bifurcation_defaults(void); /* 10 runs, 1000, 50, seed 1 */

/* friction-oscillator's brute-force bifurcation diagram (thesis 2.4):
 * sticking displacements, Poincare sections and asymmetry of each run. */
cm_status cm_analysis_bifurcation(const cm_analysis *a, const cm_bifurcation_options *o, char *msg,
                         size_t msg_size);

typedef struct cm_lyapunov_options {
    cm_axis x, y;              /* the grid, 1..2000 values each */
    int periods;               /* 1..10^6 */
    double d0;                 /* the perturbation, 1e-9..1e-3 */
    const double *from;        /* the start of a map model (dim values), or NULL: its region's centre */
    int n_from;
    const char *const *curves; /* files of `cellmap continue --curves` drawn over the figure */
    int n_curves;              /* 0..8 */
} cm_lyapunov_options;
cm_lyapunov_options cm_lyapunov_defaults(void); /* 600 periods, d0 = 1e-8 */

/* The largest Lyapunov exponent over a grid of two parameters (thesis
 * 2.6; friction-oscillator by its own estimator, any map model). */
cm_status cm_analysis_lyapunov(const cm_analysis *a, const cm_lyapunov_options *o, char *msg,
                      size_t msg_size);

typedef struct cm_sweep_options {
    const char *name;      /* the parameter */
    const double *values;  /* 2..200 increasing values */
    int n_values;
    const char *region;    /* "LO:HI[,LO:HI...]"; NULL: the model's example region */
    const int64_t *cells;  /* cells per dimension (n_cells of them), or NULL: 1000 a side */
    int n_cells;
    const double *near_lo, *near_hi; /* the window counted (n_near dimensions), or NULL */
    int n_near;
    int refine;            /* bisections of each change of the count, 0..40 */
    int max_steps;         /* of cell mapping, 0: 1 */
    int by_groups;         /* 1: count cell mapping's groups, not the system's attractors */
    const char *fractions; /* the tracked attractors' basin shares per value as CSV, or NULL */
    double match_within;   /* tracking's distance, a share of the region; 0: 0.05 */
    const char *keep;      /* a directory (made if missing): each value solved into
                              NAME=VALUE.cmdb there, as cm_db_create would; NULL: in memory */
    int no_seeds;          /* 1: births and deaths where the lattice shows them, no attractor
                              followed from a neighbouring value's (`sweep --no-seeds`) */
} cm_sweep_options;

/* A model solved at each value of one parameter, its attractors and
 * sticking zones counted in the window, the attractors tracked across the
 * values (`cellmap sweep`): a->csv the counts per value, o->fractions the
 * basin shares, a->png those shares stacked against the parameter. */
cm_status cm_analysis_sweep(const cm_analysis *a, const cm_sweep_options *o, char *msg, size_t msg_size);

typedef struct cm_continue_options {
    const char *vary;         /* S, S0, Omega or phi */
    double lo, hi;            /* its range; the model's value must lie in it */
    int direction;            /* 1: up, -1: down, 0: both ways */
    int switch_pd;            /* 1: switch to the period-doubled branches */
    const double (*from)[3];  /* starts (x, v, value; NaN x: simulate, NaN value: the model's) */
    int n_from;               /* 0..8; 0: one start simulated at the model's value */
    int period;               /* 0: the smallest that the start settles on; else 1..64 */
    int max_points;           /* 2..10^6; 0: 5000 */
    const char *events;       /* the events as CSV, or NULL */
    const char *curve;        /* NAME2 (S, S0, Omega) of the fold and PD curves, or NULL */
    double lo2, hi2;          /* its range */
    const char *curves;       /* those curves as CSV (with curve) */
} cm_continue_options;
cm_continue_options cm_continue_defaults(void); /* up, 5000 points */

/* Branches of friction-oscillator's periodic solutions followed in one
 * parameter (thesis 2.5): points, events, the diagram and the curves. */
cm_status cm_analysis_continue(const cm_analysis *a, const cm_continue_options *o, char *msg,
                      size_t msg_size);

#endif /* CELLMAP_EXPERIMENTAL */

#ifdef __cplusplus
}
#endif

#endif
