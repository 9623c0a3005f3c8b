/* src/args.h - command-line helpers shared by the subcommands.
 * Bad usage prints "cellmap CMD: problem (hint)" and gives exit status 2. */
#ifndef CM_SRC_ARGS_H
#define CM_SRC_ARGS_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "lib/parse.h"
#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "lib/project.h"

/* EXIT_INTERRUPTED: stopped by Ctrl-C (128 + SIGINT, as shells report it). */
enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_USAGE = 2, EXIT_INTERRUPTED = 130 };
#define MAX_PARAM_TEXTS MODEL_SPEC_TEXTS

/* Cursor over argv; options are "--name VALUE" or "--name=VALUE". */
typedef struct cli {
    const char *cmd; /* subcommand name, for messages */
    int argc;
    char **argv;
    int i;
    const char *opt;   /* current option name */
    const char *value; /* its value, when it takes one */
} cli;

/* Prints the usage error and returns EXIT_USAGE. */
int cli_usage_error(const cli *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The one wording for an argument no rule of the command takes: "unknown
 * option '--x'" for what starts with '-', "unexpected argument 'x'" for
 * anything else (a second file name, a stray word). Returns EXIT_USAGE. */
int cli_stray(const cli *c);

/* Advances to the next argument. Returns false at the end. */
bool cli_next(cli *c);
/* True when the current argument is option `name`; takes its value if
 * needs_value (a missing value is reported and *error set). */
bool cli_is(cli *c, const char *name, bool needs_value, int *error);

/* Handles --mem BYTES (at least 1M); true if the current option was it. */
bool cli_take_mem(cli *c, uint64_t *mem, int *error);
/* Handles option `name` with an integer in lo..hi; true if the current
 * option was it. */
bool cli_take_int(cli *c, const char *name, int lo, int hi, int *out, int *error);
/* The same for a number in lo..hi. */
bool cli_take_double(cli *c, const char *name, double lo, double hi, double *out, int *error);
/* Handles --size WxH with W in min_w..max_side and H in min_h..max_side;
 * true if the current option was it. */
bool cli_take_size(cli *c, int min_w, int min_h, int max_side, int *w, int *h, int *error);

/* The outputs of the analysis commands (chart_outputs, lib/outfile.h). */
/* Takes the current option if it is one of those (--size at least min_w x
 * min_h); true if it was. */
bool chart_outputs_take(cli *c, chart_outputs *o, int min_w, int min_h, int *error);
/* After the options: --json and a table or image on standard output, or
 * both on it, are usage errors. Returns 0 or the error's status. */
int chart_outputs_check(const cli *c, const chart_outputs *o);
/* The limits of --max-steps and --threads, which several commands take. */
enum { MAX_STEPS_LIMIT = PROJECT_MAX_STEPS, THREADS_LIMIT = 1024 };
/* Where a command's report goes: stdout, or stderr when one of its
 * outputs (any may be NULL) is standard output ("-", /dev/stdout). */
FILE *report_stream(const char *out1, const char *out2, const char *out3);

/* The options every model-driven command shares: a model_spec
 * (lib/project.h). */
typedef model_spec model_opts;

/* Handles --model, --param and --model-lib (loaded at once); returns true
 * if the current option was one. */
bool model_opts_take(cli *c, model_opts *mo, int *error);
/* Builds the model; prints the problem and returns EXIT_USAGE on failure. */
int model_opts_build(const cli *c, const model_opts *mo, cm_model *m);

/* A branch's options (branch_spec, lib/param_grid.h): --from X[,Y...],
 * --branch P=LO:HI, --direction up|down, --ds-max D, --max-points N; true
 * if the current option was one. */
bool branch_opts_take(cli *c, branch_spec *b, int *error);
/* After the options: --from given, and the settings that need a branch
 * (those of branch_spec, and `extra`, named, when set) only with one.
 * Returns 0 or the error's status. */
int branch_opts_check(const cli *c, const branch_spec *b, bool extra, const char *extra_name);

/* --region LO:HI[,LO:HI...] and --cells N[xM...] (lib/project.h). */
typedef lattice_spec lattice_opts;

/* Handles --region and --cells; true if the current option was one. */
bool lattice_opts_take(cli *c, lattice_opts *lo, int *error);
/* Builds the lattice and box for the model (its default region from
 * models, plugins included); prints the problem and returns EXIT_USAGE on
 * failure. */
int lattice_opts_build(const cli *c, const lattice_opts *lo, const cm_model *m,
                       const cm_model_set *models, cm_lattice *lat, cm_box *box);

/* The database a command is given to read or resume, checked before any
 * work (project_probe). Prints "cellmap CMD: problem" and returns
 * EXIT_USAGE if it is not one this cellmap reads; EXIT_OK. */
int cli_input_check(const char *cmd, const char *path);

/* project_open_cluster, saying "cellmap CMD: problem" on failure
 * (EXIT_FAIL, nothing left open); EXIT_OK. */
int cli_open_read(const char *cmd, const char *path, uint64_t mem_budget, cm_store **s,
                  cm_store_info *info, cm_cluster *c);

/* Tells the user that a resumed file was upgraded from format version
 * `from` (project_resume; nothing when from is 0). */
void cli_said_upgrade(const char *cmd, const char *path, int from);

/* param_sweep_base for the command's model options: the problem said as
 * a usage error (EXIT_USAGE), else EXIT_OK. */
int sweep_check(const cli *c, const model_opts *mo, const char *only, const param_axis *ax,
                int n_ax, cm_params *base);

/* Command line joined by spaces (for provenance). */
void join_argv(int argc, char **argv, char *buf, size_t size);

#endif
