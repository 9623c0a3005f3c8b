/* lib/session.h - an explore session: a view of a cluster database moved
 * over state space (view, pan, zoom, goto, extend), each move computing
 * exactly the cells it uncovers as new regions and joining them (thesis
 * 4.6.4); the view drawn, counted and queried. The command `cellmap
 * explore` (src/explore.c) reads its language and prints what these calls
 * return; benchmarks, the Python module and a server drive it directly.
 *
 * Every join is committed to the database before the call returns, and so
 * is the view once its cells are, so a session killed at any point
 * resumes from its last commit: moving to the same views again computes
 * only what is missing, in the same regions (cellmap/cover.h). The file
 * keeps three notes (docs/format.md): note.explore.view, the view as
 * "X0:X1 Y0:Y1[ at V3,V4,...]" (lib/project.h: project_view_note);
 * note.explore.depth, "LO:HI,..." cells of dimensions 3.. of models of
 * more than two dimensions; note.explore.journal, a script run's progress
 * (session_journal_begin).
 *
 * A session is used by one thread at a time; its computations use
 * `threads` OpenMP threads. Nothing is printed: each call returns a status
 * and says why in msg, and on failure the session is as before the call
 * (what it computed and committed is kept). */
#ifndef CM_LIB_SESSION_H
#define CM_LIB_SESSION_H

#include <stdbool.h>

#include "cellmap/view_keep.h"
#include "lib/attractor_report.h"
#include "lib/figure.h"
#include "lib/project.h"

/* How to open (or create) the session's database. */
typedef struct session_options {
    const char *path;
    model_spec mo; /* mo.name NULL: the file must exist */
    double cell_size[CM_MAX_DIM], origin[CM_MAX_DIM];
    int n_cell_size, n_origin;
    const char *depth_text; /* LO:HI,... of dimensions 3.. (models of more than two) */
    int max_steps;          /* 0: 1 for a new file */
    int threads;            /* 0: every core */
    uint64_t mem;           /* 0: project_default_mem() */
    uint64_t max_new_cells; /* most cells one command may compute; 0: 2^28 */
    const char *command;    /* for provenance */
} session_options;

typedef struct session {
    const char *path;
    cm_model model;
    cm_model_set models; /* the plugins the model may come from */
    int have_model;
    cm_store *store;
    cm_cluster c;
    int max_steps, threads;
    int dim, view_dims; /* view_dims: min(dim, 2) */
    int have_view;
    int view_unsaved; /* the view changed since it was written to the file */
    int damaged;      /* a call found the file damaged: it is not written again */
    int grew;         /* regions were added since the attractors were written */
    double lo[2], hi[2];          /* the view in state coordinates */
    int64_t depth_lo[CM_MAX_DIM]; /* dimensions >= 2: the cells computed */
    int64_t depth_hi[CM_MAX_DIM];
    int64_t slice[CM_MAX_DIM]; /* dimensions >= 2: the cell shown */
    uint64_t max_new_cells; /* most cells one step computes (bounded by --mem) */
    int mem_given;          /* --mem was given */
    cm_gl *gl; /* kept between renders (made by the first); NULL until then */
    /* what renders found following the view's exits, so that a pan's
     * render follows only the exits it has not met (made by the first
     * render; NULL until then, or when there was no memory for it) */
    cm_exit_memo *exit_memo;
    /* what the view's nodes resolved to, so that a pan's flatten resolves
     * only the nodes whose outcome changed (made by the first render or
     * stats; NULL until then, or when there was no memory for it) */
    cm_resolve_cache *resolve_cache;
    /* the last rendered view's cells' ends and the exits they reach, so
     * that a pan's render by attractors finds only its new cells' (made by
     * the first such render; NULL until then, or when there was no memory
     * for it) */
    cm_view_keep *view_keep;
    /* the journal of a script's run (session_journal_begin): which line
     * runs, and where a killed run of the same script stopped */
    uint64_t script_hash; /* 0: no journal (stdin, the prompt) */
    long line;            /* the script's line that runs (the caller sets it) */
    long resume_line;     /* 0: nothing to resume; else its extensions up to here are done */
    int resume_step;      /* > 0: resume_line's extend stopped in this step, on resume_tile */
    cm_box resume_tile;
} session;

/* What opening told: the file's format was upgraded from this version (0:
 * not), and whether a failure is the options' (a usage error) rather than
 * the file's or the system's. */
typedef struct session_opened {
    int upgraded_from;
    bool bad_options;
} session_opened;

/* For a program that draws view after view (explore, serve), called once
 * at its start: glibc then keeps the memory one view frees for the next.
 * Blocks up to 32 MiB come from the heap rather than mappings of their own,
 * and the heap's top goes back to the system only beyond 64 MiB free.
 * Otherwise each view's arrays (4 MB each for 1000 x 1000 cells) are mapped
 * afresh and the kernel zeroes every page on first touch: 2-8 ms of a
 * 1000 x 1000 render (docs/engine.md). A session's peak memory stays as it
 * was; what it frees stays resident up to that peak. Process-wide, so it
 * is the program's call, never made by the library itself. */
void session_keep_freed(void);

/* Opens path (creating it from the model options if it does not exist).
 * Whatever the status, session_close ends it. */
cm_status session_open(session *s, const session_options *o, session_opened *opened, char *msg,
                       size_t msg_size);

/* What a move or an extension step computed. */
typedef struct session_work {
    uint64_t cells;
    uint32_t regions, new_groups, straddling, affected;
    double seconds;
} session_work;

/* Moves the view to lo..hi (dimensions 0 and 1; a view across the seam of
 * a periodic coordinate is moved back inside) and, for models of more than
 * two dimensions, to the slice (cells of dimensions 2.., NULL: the same)
 * and computes what it uncovers. verb names the move in messages. */
cm_status session_move(session *s, const double *lo, const double *hi, const int64_t *slice,
                       const char *verb, session_work *done, char *msg, size_t msg_size);

/* The slice of "Z,W,..." (state coordinates of dimensions 3..): the cells
 * inside the session's depth, into slice[2..]. */
cm_status session_slice(const session *s, const char *text, int64_t *slice, char *msg,
                        size_t msg_size);

/* CM_OK when the session has a view, else CM_EINVAL saying how to start one. */
cm_status session_need_view(const session *s, const char *verb, char *msg, size_t msg_size);

/* The view as the note keeps it ("X0:X1 Y0:Y1[ at Z,...]"). */
void session_view_text(const session *s, char *out, size_t size);

/* The cells the view touches (all of its depth) and the cells drawn (the
 * slice). */
void session_view_cells(const session *s, cm_box *box);
void session_shown_cells(const session *s, cm_box *box);

/* Sets box's dimension to the session's and its dimensions 2.. to the
 * slice drawn (one layer), leaving dimensions 0 and 1. */
void session_slice_box(const session *s, cm_box *box);

/* One `extend auto` step done. */
typedef struct session_step {
    int step;
    cm_box tile;
    bool recorded;   /* the tile recorded before an interruption, not chosen now */
    uint64_t escaping, all_escaping; /* the sequences that lead to the tile, and all escaping */
    session_work work;
} session_step;
typedef void (*session_step_fn)(void *user, const session_step *step);

/* How an extension ended. */
typedef struct session_extended {
    bool repeated; /* done in the run that stopped (a resumed script's line): nothing done */
    bool stopped;  /* nothing escapes next to the cluster: why in stop */
    char stop[256];
} session_extended;

/* Up to `steps` times (1..1000) adds the tile of tile's size (NULL: the
 * view's) where the most sequences escape, calling step_done (may be
 * NULL) after each; in a journaled run (session_journal_begin), a line
 * done before is not repeated and the step that was interrupted is
 * completed on its recorded tile. */
cm_status session_extend(session *s, const cm_box *tile, int steps, session_step_fn step_done,
                         void *user, session_extended *out, char *msg, size_t msg_size);

/* The cells of the rectangle lo..hi (every dimension), by the lattice's
 * rectangle-to-box rule. */
cm_status session_rect_box(const session *s, const double *lo, const double *hi, cm_box *box,
                           char *msg, size_t msg_size);

/* The cells of box the cluster lacks, computed and joined, each join
 * committed; the view stays. */
cm_status session_add_box(session *s, const cm_box *box, session_work *done, char *msg,
                          size_t msg_size);

/* A script file's run is journaled in the file (note.explore.journal):
 * each `extend auto` step's tile before it is computed, each extend line
 * when done, the script's end. script_hash identifies the script (its
 * bytes; not 0). If the journal shows that a run of this same script
 * stopped before its end (killed, or a failed line), this run resumes it:
 * its lines run again (views, pans, renders and exports compute and write
 * the same), but the extension steps done before are not repeated (the
 * interrupted step's recorded tile is completed), so that the file ends as
 * one run would have left it; s->resume_line and s->resume_step say
 * where. */
cm_status session_journal_begin(session *s, uint64_t script_hash, char *msg, size_t msg_size);

/* The journal's end: the script ran to its end (a later run of it is a
 * new run). */
cm_status session_journal_end(session *s, char *msg, size_t msg_size);

/* The view's shown cells drawn as po says (lib/figure.h; po->path or
 * po->svg: the files), by the system's attractors (found for the whole
 * cluster, as render finds them) or by groups (po->by). No output may
 * replace the session's database or a file po reads. */
cm_status session_render(session *s, png_opts *po, char *msg, size_t msg_size);

/* The cells of box (a slice: dimensions 2.. one cell wide) flattened into
 * flat and labelled by the system's attractors as render labels them, into
 * a new *labels (flat->ncells entries, the caller frees it) with the
 * attractors in att (cm_attractors_free); the view stays. On failure
 * nothing is left to free. */
cm_status session_labels(session *s, const cm_box *box, cm_region *flat, int32_t **labels,
                         cm_attractor_set *att, char *msg, size_t msg_size);

/* The figure of the rectangle lo..hi (dimensions 0 and 1; the slice in
 * the others) as `render` draws a file's (po: its files and options, its
 * attractors found afresh when the cluster grew since they were stored);
 * the view stays. */
cm_status session_figure(session *s, const png_opts *po, const double lo[2], const double hi[2],
                         char *msg, size_t msg_size);

/* What `stats` counts in the view's shown cells. */
typedef struct session_stats {
    cm_region flat;         /* the shown cells */
    cm_group_info *groups;  /* the cluster's groups (entry k: group k + 1) */
    uint64_t cells, missing, groups_in_view, cluster_cells, file_bytes;
    uint64_t *in_view;      /* cells per group id; [0]: the sink's domain */
    cm_attractor_set att;   /* the system's attractors */
    uint64_t *by_label;     /* cells per attractor label, at label + 2 (-2 and -1 first) */
    uint64_t memory_bytes, resident_bytes; /* the cluster's, in memory */
    uint64_t view_bytes; /* what the session keeps of its views: the kept view, the exit memo
                            and the resolve cache (outside --mem) */
} session_stats;

/* Counts the view (the session needs one); session_stats_free frees it,
 * whatever the status. */
cm_status session_count(session *s, session_stats *v, char *msg, size_t msg_size);
void session_stats_free(session_stats *v);

/* The file's records as they are now (for an export of the session's own
 * cluster, lib/export.h, without opening the file again). */
cm_status session_records(session *s, cm_store_info *info, char *msg, size_t msg_size);

/* Writes the view to the file if it changed since it was last written. A
 * file found damaged is never written again. */
cm_status session_save(session *s, char *msg, size_t msg_size);

/* Writes the attractors (when the cluster grew) and the view, and closes
 * the database. Returns the first failure. */
cm_status session_close(session *s, char *msg, size_t msg_size);

#endif
