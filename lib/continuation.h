/* lib/continuation.h - branches of the friction oscillator's periodic
 * solutions followed in one parameter (thesis 2.5, docs/models.md 9.9)
 * over models/fo_continuation.h's kernel: from each start (simulated to a
 * periodic solution, or given) one way or both, the period-doubled
 * branches switched to (--switch), their points and events (SN, PD, NS,
 * CS, T) collected; written as CSV, as the thesis' diagrams (Figs.
 * 2.17-2.19) and as two-parameter curves of the folds and period
 * doublings. Calls return a status with the problem in msg (CM_EINVAL:
 * the request's, as a start outside the range); nothing is printed. */
#ifndef CM_LIB_CONTINUATION_H
#define CM_LIB_CONTINUATION_H

#include <stdbool.h>

#include "lib/project.h"
#include "models/fo_continuation.h"

enum { MAX_STARTS = 8, MAX_BRANCHES = 64, MAX_MARKS = 8 };

/* The diagram's panels. */
enum { PANEL_X_MAX = 0, PANEL_STOPS, PANEL_PSI, PANELS };
static const char *const panel_names[PANELS] = {"x_max", "stops", "psi"};

/* What to follow and what to write (the command's options). */
typedef struct cont_args {
    model_spec mo;
    char vary[16], vary2[16];
    double lo, hi, lo2, hi2;
    /* the starts: x, v (NaN: simulate) and the parameter's value (NaN: --param's) */
    double from[MAX_STARTS][3];
    int has_vary, n_from, down, both, switch_pd, period, max_points, width, height;
    int panels[PANELS], n_panels;
    double mark_at[MAX_MARKS]; /* --mark P=TEXT: TEXT added to the label of the event nearest P */
    const char *mark_text[MAX_MARKS];
    int n_marks;
    const char *csv, *events, *png, *curves;
    bool json, quiet;
} cont_args;

/* --panels "x_max,stops,psi" (any of them, in any order, each once) and
 * --mark P=TEXT (at most MAX_MARKS) into a; false if the text is none. */
bool continuation_parse_panels(const char *text, cont_args *a);
bool continuation_parse_mark(const char *text, cont_args *a);

/* ---- the branches, collected ---- */

typedef struct tagged_point {
    int branch;
    cm_fo_solution s;
} tagged_point;

typedef struct tagged_event {
    int branch;
    cm_fo_branch_event e;
} tagged_event;

typedef struct branch_info {
    cm_fo_solution start;
    int direction, stop;
    uint64_t points;
} branch_info;

typedef struct collected {
    tagged_point *points;
    uint64_t n, cap;
    tagged_event *events;
    uint64_t n_events, cap_events;
    branch_info branches[MAX_BRANCHES];
    int n_branches;
    bool out_of_memory;
} collected;

/* What was followed: the model, the varied parameter's index and start
 * value, the branches, and the curves written. */
typedef struct cont_result {
    cm_model m;
    const cm_fo *o; /* m's oscillator */
    int param;      /* cm_fo_param_of(a->vary) */
    double p0;      /* its value in the model */
    collected col;
    int n_curves;
} cont_result;

/* Fills the diagram's panels (all three when none is picked) and size
 * (900x1100, or 450 per panel) and checks them. */
cm_status continuation_layout(cont_args *a, char *msg, size_t msg_size);

/* Checks the request, builds the model and follows every branch it asks
 * for; r is freed by continuation_result_free whatever the status. */
cm_status continuation_compute(cont_args *a, cont_result *r, char *msg, size_t msg_size);

/* The branch points (a->csv) and events (a->events) as CSV, the diagram
 * (a->png: the panels a->panels picks, stable green, unstable red, events
 * black and labelled on the top panel) and, from every fold and period
 * doubling, its curve in (a->vary, a->vary2) both ways (a->curves; their
 * number in r->n_curves), each when given. */
cm_status continuation_write(const cont_args *a, cont_result *r, char *msg, size_t msg_size);

void continuation_result_free(cont_result *r);

/* The thesis' label of an event (SN_2s, PD_1a, CS_s) and its kind in words. */
void continuation_event_label(const cm_fo_branch_event *e, char *out, size_t size);
const char *continuation_event_kind(const cm_fo_branch_event *e);

#endif
