/* src/explore.h - the explore session language: lines of view, pan, zoom,
 * goto, extend auto, render, stats, export, save and quit read into the
 * calls of lib/session.h, and what they did printed as status lines. The
 * command `cellmap explore` feeds it lines from a script or a prompt;
 * benchmarks and the fuzz target drive it directly. */
#ifndef CM_SRC_EXPLORE_H
#define CM_SRC_EXPLORE_H

#include <stdio.h>

#include "lib/session.h"
#include "src/args.h"

typedef struct explore {
    session s;
    FILE *out; /* status lines; NULL: quiet */
    int quit;  /* a quit line was read */
} explore;

/* Opens the session (lib/session.h: session_open). Returns EXIT_OK,
 * EXIT_USAGE (bad options) or EXIT_FAIL, having printed "cellmap explore:
 * problem"; explore_close ends it whatever it returned. */
int explore_open(explore *e, const session_options *o, FILE *out);

/* Runs one line (comments and blank lines do nothing). On failure msg says
 * why and the session is as before the line (what it computed is kept). */
cm_status explore_exec(explore *e, const char *line, char *msg, size_t msg_size);

/* session_journal_begin, saying on the status lines what a resumed run
 * of the script will not repeat. */
cm_status explore_journal_begin(explore *e, uint64_t script_hash, char *msg, size_t msg_size);

/* Saves the view and the attractors and closes the database (session_close). */
cm_status explore_close(explore *e, char *msg, size_t msg_size);

/* The commands, one per line, for `help` and --help. */
extern const char session_help[];

/* The options that open (or make) a session's file, as explore and serve
 * take them: the model (--model, --model-lib, --param), the lattice
 * (--cell-size, --origin), --depth, --max-steps, --threads, --mem; true
 * if the current option was one of them. */
bool session_opts_take(cli *c, session_options *o, int *err);

#endif
