/* lib/project.h - a .cmdb project as the commands and the library use one:
 * opened to read (render, export, info), created or resumed to be extended
 * (solve --db, explore), with the rules they share: a file is checked read-only before
 * anything is written to it, older formats are upgraded only once the file
 * proves to be the caller's, new files carry the command line, plan and a
 * reproducible creation time. */
#ifndef CM_LIB_PROJECT_H
#define CM_LIB_PROJECT_H

#include "cellmap/extend.h"
#include "cellmap/join.h"
#include "cellmap/model.h"
#include "cellmap/store.h"
#include "models/registry.h"

/* The most steps a cell's sequence is followed in one solve (--max-steps). */
enum { PROJECT_MAX_STEPS = 1000000 };

/* A model as a user names it: the name, its parameter texts ("k=v,...",
 * each applied in turn over the defaults) and the plugins it may come from
 * (the built-in models and those loaded into set). */
enum { MODEL_SPEC_TEXTS = 32 };
typedef struct model_spec {
    const char *name;
    const char *texts[MODEL_SPEC_TEXTS];
    int n_texts;
    cm_model_set set;
} model_spec;

/* A box of state space cut into cells as a user gives it: its ranges
 * ("LO:HI[,LO:HI...]"; NULL: the model's example region) and the cells
 * per dimension (n_cells 0: 1000 a side in 1-D and 2-D, else 100). */
typedef struct lattice_spec {
    const char *region_text;
    int64_t cells[CM_MAX_DIM];
    int n_cells;
} lattice_spec;

/* The lattice whose origin is the region's lower corner, and the box of
 * the region's cells, for model m (its example region from models,
 * plugins included): CM_EINVAL with the problem in msg when the region or
 * the cells do not fit the model or a region's limits. */
cm_status lattice_of_spec(const lattice_spec *spec, const cm_model *m, const cm_model_set *models,
                          cm_lattice *lat, cm_box *box, char *msg, size_t msg_size);

/* The plugin the model `name` of spec's set comes from (NULL: built in). */
const cm_model_lib *model_spec_lib(const model_spec *spec, const char *name);

/* The model spec names, built with its parameters' texts (*m released by
 * the caller with cm_model_release). */
cm_status model_spec_build(const model_spec *spec, cm_model *m, char *msg, size_t msg_size);

/* The example region of the model spec names (dim coordinates) into lo
 * and hi: CM_EINVAL when it has none. */
cm_status model_spec_region(const model_spec *spec, int dim, double *lo, double *hi, char *msg,
                            size_t msg_size);

/* Its centre into x. */
cm_status model_spec_centre(const model_spec *spec, int dim, double *x, char *msg,
                            size_t msg_size);

/* The image y of x under m's map, with step's return value, and the
 * flow's time it took in *flight: a stroboscopic map's period, a Poincare
 * map's return time to its section (without an image: how long the orbit
 * was followed, m->flow.t_max when the section was not reached); NAN for
 * a map that is no flow's. */
int model_image(const cm_model *m, const double *x, double *y, double *flight);

/* Whether path is a database this cellmap reads, checked before any work
 * (cm_store_probe: it exists, is readable and is a cellmap database of a
 * format this version reads): CM_OK, else why not in msg. Damage inside
 * is found when it is opened. */
cm_status project_probe(const char *path, char *msg, size_t msg_size);

/* Opens path read-only in a snapshot and reads what it says about itself;
 * a file with no region yet is refused. map_reads: reads through a memory
 * map (cm_store_map_reads), for commands that read its records only (info,
 * export --groups). The caller ends the snapshot and closes *s, whatever
 * the status (*s may be NULL). */
cm_status project_open_records(const char *path, bool map_reads, cm_store **s,
                               cm_store_info *info, char *msg, size_t msg_size);

/* Opens path read-only, reads what it says about itself and restores its
 * cluster (paged out; regions are read back on demand within mem_budget
 * bytes). On failure nothing is left open (*s NULL) and msg says why. */
cm_status project_open_cluster(const char *path, uint64_t mem_budget, cm_store **s,
                               cm_store_info *info, cm_cluster *c, char *msg, size_t msg_size);

/* The view an explore session saved in the file, note.explore.view:
 * "X0:X1 Y0:Y1[ at V3,V4,...]" (explore writes it; V3.. are the slice's
 * states in dimensions 3..). The ranges of the first dims (1 or 2)
 * dimensions go to lo and hi, the text after " at " to slice (""
 * without). CM_ENOTFOUND when the file has none, CM_EFORMAT when the
 * note is not such a view. */
cm_status project_view_note(cm_store *s, int dims, double lo[2], double hi[2], char *slice,
                            size_t slice_size);

/* Closes what project_open_read, project_create or project_resume opened. */
void project_close(cm_store *s, cm_cluster *c);

/* The model a file was made with, rebuilt from its name and parameters
 * (which must rebuild exactly). */
cm_status model_of_store(const cm_store_info *info, cm_model_set *set, cm_model *m, char *msg,
                         size_t msg_size);

/* The memory budget (bytes of cell arrays) of a cluster in a file when
 * none is given (an explore session, solve --db): an eighth of the
 * machine's memory, at most 128 MiB and at least 16 MiB, so that a long
 * session's memory stays flat; regions beyond it are paged to the file
 * (they are there already) and read back on demand. */
enum { PROJECT_MEM_MAX_MIB = 128, PROJECT_MEM_MIN_MIB = 16 };
uint64_t project_default_mem(void);

/* A new file at path for model m, lattice, command line and plan (created
 * at SOURCE_DATE_EPOCH, else time 0), replacing an older cellmap database
 * there once cm_store_finish says the new cluster is complete (never
 * another file), and an empty cluster c saved into it; m
 * labels its groups' kinds and must outlive the store. */
cm_status project_create(const char *path, const cm_model *m, const cm_model_lib *lib,
                         const cm_lattice *lat, const char *command, const char *plan,
                         cm_store **s, cm_cluster *c, char *msg, size_t msg_size);

/* Says whether a file is the caller's to extend (model, parameters,
 * lattice, plan...) and gives the model to extend it with (*model, which
 * must outlive the store); anything but CM_OK refuses it with the message. */
typedef cm_status (*project_fits_fn)(void *user, const cm_store_info *info,
                                     const cm_model **model, char *msg, size_t msg_size);

/* Resumes path to extend it: reads what it says about itself (into *info)
 * read-only, asks `fits`, upgrades a file of an older format in place
 * (*upgraded_from: the version it had, 0 when none was needed; the caller
 * tells its user), opens it for writing and restores its cluster into c
 * (paged out, the store attached as pager). A refused file is left
 * byte-identical. */
cm_status project_resume(const char *path, project_fits_fn fits, void *user, cm_store **s,
                         cm_store_info *info, cm_cluster *c, int *upgraded_from, char *msg,
                         size_t msg_size);

/* How a solve grows its project: each box cut into split[d] nearly equal
 * parts per dimension (fewer where it has fewer cells), solved with opt and
 * joined in order; then up to `extend` extension steps (thesis 4.6.4), each
 * the neighbouring tile where most sequences escape, clipped to bounds
 * (NULL: anywhere), until fewer than escape_below of the cells escape. */
typedef struct project_plan {
    int nsplit;
    int64_t split[CM_MAX_DIM];
    cm_scm_options opt;
    int extend;
    double escape_below;
    const cm_box *bounds;
    const char *bounds_text; /* as the user gave them, for the plan's text */
    /* optional: called after each join, once it is committed to the store;
     * anything but CM_OK stops the solve with it (cm_joined_fn) */
    cm_joined_fn joined;
    void *joined_user;
} project_plan;

/* The plan as text: what a resumed solve must repeat exactly (the box, the
 * split, the steps). */
void project_plan_text(const project_plan *p, const cm_box *box, char *out, size_t size);

/* The whole number after the word `key` in a plan's text ("... max-steps
 * 50 ..."), within lo..hi: CM_OK, CM_ENOTFOUND when the plan has no such
 * word, CM_EFORMAT when what follows it is not such a number. */
cm_status project_plan_int(const char *plan, const char *key, int lo, int hi, int *value);

/* The box cut as the plan says: returns the number of parts; boxes (may be
 * NULL: only counted) receives them. */
uint32_t project_split(const project_plan *p, const cm_box *box, cm_box *boxes);

/* The one driver that solves regions and joins them: boxes (disjoint, and
 * outside the cluster's regions) solved with opt as new regions and joined
 * to c in order, each join committed to s (NULL: no database) before then
 * (may be NULL) is called; stats (may be NULL) sums the joins. */
cm_status project_solve_boxes(cm_cluster *c, cm_store *s, const cm_model *m,
                              const cm_scm_options *opt, const cm_box *boxes, uint32_t n,
                              cm_joined_fn then, void *user, cm_join_stats *stats, char *msg,
                              size_t msg_size);

/* Solves the parts of box (cut as the plan says) that the cluster lacks
 * with the plan's options and joins them (project_solve_boxes, with the
 * plan's joined callback); stats (may be NULL) sums the joins. */
cm_status project_add_box(cm_cluster *c, cm_store *s, const cm_model *m, const project_plan *p,
                          const cm_box *box, cm_join_stats *stats, char *msg, size_t msg_size);

/* One extension step, as done. */
typedef struct project_step {
    cm_box box;
    uint64_t escaping, all_escaping, cluster_cells;
    uint32_t new_groups, straddling;
    double seconds;
} project_step;
typedef void (*project_step_fn)(void *user, const project_step *step, int k);

/* Computes extension step k on the tile chosen (or, recorded, the one a
 * resumed run recorded; started: when the step began, cm_seconds):
 * CM_OK, CM_ENOTFOUND to end the extension here (msg says why; no
 * error), or a failure. */
typedef cm_status (*project_tile_fn)(void *user, int k, const cm_extend_choice *choice,
                                     bool recorded, double started, char *msg, size_t msg_size);

/* The one extension loop (thesis 4.6.4), for solves and explore sessions:
 * steps first..last, each the neighbouring tile of tile's size where most
 * of the cluster's escaping sequences go (within bounds, NULL: anywhere;
 * recorded_first, when not NULL: step first's tile, recorded by a run
 * that stopped), computed by `compute`. Ends early, with CM_OK and why in
 * stop, when no sequence escapes into a neighbour or compute says so;
 * *done: the steps computed. No region's cells are read to choose a tile. */
cm_status project_extend_tiles(cm_cluster *c, const cm_box *tile, const cm_box *bounds, int first,
                               int last, const cm_box *recorded_first, project_tile_fn compute,
                               void *user, int *done, char *stop, size_t stop_size, char *msg,
                               size_t msg_size);

/* The extension of a cluster whose first tile is `tile`: finishes a step a
 * resumed cluster had begun, then adds tiles (calling step_done after each,
 * which may be NULL) until the plan's steps are done, too few sequences
 * escape or none escapes into a neighbour; *steps: the steps done now;
 * stop: why it ended. No region's cells are read to choose a tile. */
cm_status project_extend(cm_cluster *c, cm_store *s, const cm_model *m, const project_plan *p,
                         const cm_box *tile, project_step_fn step_done, void *user, int *steps,
                         char *stop, size_t stop_size, char *msg, size_t msg_size);

/* The names of the file's state coordinates (CM_MAX_DIM entries): its
 * model's (cm_model_coord_name), or x0, x1, ... for a model this cellmap
 * does not know. */
void project_state_names(const cm_store_info *info, const char **names);

#endif
