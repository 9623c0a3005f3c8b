/* cellmap - cell mapping and global dynamics from the command line. */
#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "lib/outfile.h"
#include "lib/parse.h"
#include "lib/ranks.h"
#include "src/args.h"
#include "src/commands.h"
#include "src/run_env.h"

/* Runs `name`, the program built and installed beside this one, with
 * argv: cellmap-serve alone links the HTTP library (src/cmd_serve.c says
 * why), cellmap-mpi alone MPI. */
static int run_beside(const char *name, char **argv, const char *why)
{
    char path[4096];
    const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 32);
    if (n > 0) { /* an absolute path */
        path[n] = '\0';
        strcpy(strrchr(path, '/') + 1, name);
        execv(path, argv);
    }
    fprintf(stderr, "cellmap: cannot run %s: %s (%s)\n", n > 0 ? path : name, strerror(errno),
            why);
    return EXIT_FAIL;
}

static int run_serve(int argc, char **argv)
{
    static char name[] = "cellmap-serve";
    (void)argc;
    argv[0] = name; /* what ps and pkill show */
    return run_beside("cellmap-serve", argv, "cellmap-serve is built and installed beside cellmap");
}

/* Under mpirun (lib/ranks.h): solve runs as cellmap-mpi, built where MPI
 * was found; other commands run on one rank. */
static int run_ranked(const char *name, char **argv)
{
    if (strcmp(name, "solve") == 0)
        return run_beside("cellmap-mpi", argv,
                          "cellmap-mpi is built beside cellmap where MPI was found: install "
                          "libopenmpi-dev and build again");
    if (ranks_launched() > 1 && ranks_launched_rank() == 0)
        fprintf(stderr, "cellmap %s: only solve runs on MPI ranks: run it without mpirun\n", name);
    return ranks_launched() > 1 ? EXIT_USAGE : -1;
}

static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *doc;
} commands[] = {
    {"models", cmd_models, "list the models, their parameters and defaults"},
    {"solve", cmd_solve, "simple cell mapping of a region: summary, PNG, database"},
    {"sweep", cmd_sweep,
     "solve a region for several values of a parameter; where attractors are absorbed"},
    {"explore", cmd_explore, "explore basins by panning and zooming a view (script or prompt)"},
    {"serve", run_serve,
     "the basin atlas in a browser: pan and zoom a cluster that grows as you look"},
    {"render", cmd_render, "draw a figure or an indexed image of a .cmdb file's basins"},
    {"info", cmd_info, "what a .cmdb cluster database holds; its size on disk and in memory"},
    {"export", cmd_export, "a .cmdb file's groups and cells as CSV, .npy or a flat SQLite table"},
    {"measure", cmd_measure,
     "a .cmdb file's basins measured: shares, basin entropy, uncertainty exponent, Wada test"},
    {"orbit", cmd_orbit, "print an orbit of a model as CSV (full precision)"},
    {"fixed-points", cmd_fixed_points, "print the regular and virtual fixed points as CSV"},
    {"equilibria", cmd_equilibria,
     "equilibria of a flow: eigenvalues, branches in a parameter, folds and Hopf points"},
    {"periodic", cmd_periodic,
     "periodic orbits of a map: multipliers, branches, folds and period-doubling cascades"},
    {"exponents", cmd_exponents,
     "the Lyapunov spectrum of one orbit (flows and maps) and its Kaplan-Yorke dimension"},
    {"lyapunov", cmd_lyapunov, "largest Lyapunov exponent over a grid of two parameters (any model)"},
    {"simulate", cmd_simulate,
     "a trajectory of the friction oscillator: events as CSV, x(t) and phase portrait"},
    {"bifurcation", cmd_bifurcation,
     "Monte Carlo bifurcation diagram of the friction oscillator, with Psi"},
    {"partition", cmd_partition,
     "the delay micro-chaos map's proof of chaos: partition, transition matrix, primitivity"},
    {"horseshoe", cmd_horseshoe,
     "horseshoes of the PD micro-chaos map: escape conditions, binary shift, entropy"},
    {"stability", cmd_stability,
     "analytic charts of the PD micro-chaos map: stability domain, fixed points, control error"},
    {"escape", cmd_escape,
     "transient chaos of the 1-D friction micro-chaos map: repeller, escape rate, mean escape number"},
    {"amplitude", cmd_amplitude,
     "amplitude-frequency diagram of the friction oscillator: (2.25), validity, stability"},
    {"continue", cmd_continue,
     "continuation of the friction oscillator's periodic solutions: branches and bifurcations"},
};

static void usage(FILE *out)
{
    fprintf(out, "usage: cellmap COMMAND [OPTIONS]   (cellmap help COMMAND, or COMMAND --help "
                 "or -h, for details)\n\n"
                 "commands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(out, "  %-14s %s\n", commands[i].name, commands[i].doc);
    fprintf(out, "\nFigures: basin figures take --png, --svg and --pdf FILE; a chart's --png FILE\n"
                 "is written as SVG or PDF where FILE ends in .svg or .pdf.\n");
}

/* Whether a command builds enough cells for huge pages to pay for a second
 * start (src/run_env.h; 1-3 ms): explore and serve always; solve and sweep
 * unless --cells asks for fewer than 2^18 cells without --split or
 * --extend (the default is 1000 a dimension). Readers of files (render,
 * export, measure) page their regions into huge pages anyway. */
static bool builds_cells(const char *name, int argc, char **argv)
{
    if (strcmp(name, "explore") == 0 || strcmp(name, "serve") == 0)
        return true;
    if (strcmp(name, "solve") != 0 && strcmp(name, "sweep") != 0)
        return false;
    uint64_t cells = UINT64_C(1) << 18;
    for (int i = 2; i < argc; i++) {
        if (strcmp(argv[i], "--split") == 0 || strcmp(argv[i], "--extend") == 0)
            return true;
        int64_t n[CM_MAX_DIM];
        int dims = 0; /* a product that wraps past 2^64 only goes without huge pages */
        if (strcmp(argv[i], "--cells") == 0 && i + 1 < argc &&
            parse_counts(argv[i + 1], n, &dims, CM_MAX_DIM))
            for (cells = 1; dims > 0; dims--)
                cells *= (uint64_t)n[dims - 1];
    }
    return cells >= UINT64_C(1) << 18;
}

/* A command's status, made a failure if its standard output was lost (a
 * full device, a closed pipe): output that did not arrive is not success. */
static int finish(const char *name, int status)
{
    char msg[256];
    if (cm_stdout_check(msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap %s: %s\n", name, msg);
        return status == EXIT_OK ? EXIT_FAIL : status;
    }
    return status;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        usage(stdout);
        return EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("cellmap %s\n", CELLMAP_VERSION);
        return EXIT_OK;
    }
    /* "cellmap help CMD" is "cellmap CMD --help" */
    char help_flag[] = "--help";
    char *help_argv[3] = {argc > 2 ? argv[2] : NULL, help_flag, NULL};
    const bool asks_help = strcmp(argv[1], "help") == 0;
    if (asks_help && argc == 2) {
        usage(stdout);
        return EXIT_OK;
    }
    if (asks_help && argc > 3) {
        fprintf(stderr, "cellmap help: one command at a time\n");
        return EXIT_USAGE;
    }
    const char *name = asks_help ? argv[2] : argv[1];
    if (!asks_help) /* returns unless a setting was missing */
        run_env_apply(argv, (strcmp(name, "explore") == 0 || ranks_launched() > 1) *
                                    RUN_ENV_PASSIVE_WAIT |
                                builds_cells(name, argc, argv) * RUN_ENV_HUGE_PAGES);
    for (int i = 2; i < argc; i++) /* -h is --help, for every command */
        if (strcmp(argv[i], "-h") == 0)
            argv[i] = help_flag;
    const int ranked = !asks_help && ranks_launched() ? run_ranked(name, argv) : -1;
    if (ranked >= 0)
        return ranked;
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(name, commands[i].name) == 0)
            return finish(name, asks_help ? commands[i].run(2, help_argv)
                                          : commands[i].run(argc - 1, argv + 1));
    fprintf(stderr, "cellmap: unknown command '%s'\n", name);
    usage(stderr);
    return EXIT_USAGE;
}
