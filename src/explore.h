/* src/explore.h - an explore session: a view of a cluster database moved
 * by commands (view, pan, zoom, goto, extend auto, render, stats, export,
 * save, quit), each computing exactly the cells it uncovers as new regions
 * and joining them (thesis 4.6.4). The command `cellmap explore` feeds it
 * lines from a script or a prompt; benchmarks drive it directly.
 *
 * Every join is committed to the database before the next command, and so
 * is the view, so a session killed at any point resumes from its last
 * commit: replaying the same script computes only what is missing, in the
 * same regions (cellmap/cover.h).
 */
#ifndef CM_SRC_EXPLORE_H
#define CM_SRC_EXPLORE_H

#include <stdio.h>

#include "cellmap/join.h"
#include "cellmap/store.h"
#include "render/gl.h"
#include "src/args.h"

/* How to open (or create) the session's database. */
typedef struct session_options {
    const char *path;
    model_opts mo; /* mo.name NULL: the file must exist */
    double cell_size[CM_MAX_DIM], origin[CM_MAX_DIM];
    int n_cell_size, n_origin;
    const char *depth_text; /* LO:HI,... of dimensions 3.. (models of more than two) */
    int max_steps;          /* 0: 1 for a new file */
    int threads;            /* 0: every core */
    uint64_t mem;           /* 0: no budget */
    uint64_t max_new_cells; /* most cells one command may compute; 0: 2^28 */
    const char *command;    /* for provenance */
    FILE *out;              /* status lines; NULL: quiet */
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
    int damaged;      /* a command found the file damaged: it is not written again */
    int grew;         /* regions were added since the attractors were written */
    double lo[2], hi[2];          /* the view in state coordinates */
    int64_t depth_lo[CM_MAX_DIM]; /* dimensions >= 2: the cells computed */
    int64_t depth_hi[CM_MAX_DIM];
    int64_t slice[CM_MAX_DIM]; /* dimensions >= 2: the cell shown */
    int quit;
    uint64_t max_new_cells; /* most cells one step computes (bounded by --mem) */
    int mem_given;          /* --mem was given */
    FILE *out;
    cm_gl *gl; /* kept between renders (made by the first); NULL until then */
    /* the journal of a script's run (session_journal_begin): which line
     * runs, and where a killed run of the same script stopped */
    uint64_t script_hash; /* 0: no journal (stdin, the prompt) */
    long line;            /* the script's line that runs */
    long resume_line;     /* 0: nothing to resume; else its extensions up to here are done */
    int resume_step;      /* > 0: resume_line's extend stopped in this step, on resume_tile */
    cm_box resume_tile;
} session;

/* Opens path (creating it from the model options if it does not exist).
 * Returns EXIT_OK, EXIT_USAGE (bad options) or EXIT_FAIL, having printed
 * "cellmap explore: problem". */
int session_open(session *s, const session_options *o);

/* Runs one line (comments and blank lines do nothing). On failure msg says
 * why and the session is as before the line (what it computed is kept). */
cm_status session_exec(session *s, const char *line, char *msg, size_t msg_size);

/* A script file's run is journaled in the file (note.explore.journal):
 * each `extend auto` step's tile before it is computed, each extend line
 * when done, the script's end. script_hash identifies the script (its
 * bytes). If the journal shows that a run of this same script stopped
 * before its end (killed, or a failed line), this run resumes it: its
 * lines run again (views, pans, renders and exports compute and write
 * the same), but the extension steps done before are not repeated (the
 * interrupted step's recorded tile is completed), so that the file ends
 * as one run would have left it. Prints what it resumes. */
cm_status session_journal_begin(session *s, uint64_t script_hash, char *msg, size_t msg_size);

/* The journal's end: the script ran to its end (a later run of it is a
 * new run). */
cm_status session_journal_end(session *s, char *msg, size_t msg_size);

/* Saves the view and closes the database. Returns the close status. */
cm_status session_close(session *s, char *msg, size_t msg_size);

/* The commands, one per line, for `help` and --help. */
extern const char session_help[];

#endif
