/* cellmap explore: a session of view, pan, zoom ... commands on a cluster
 * database, from a script, from stdin, or at a prompt with line editing
 * (libedit) when stdin is a terminal. */
#include <editline/readline.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "src/args.h"
#include "src/commands.h"
#include "src/explore.h"
#include "lib/project.h"

static const char explore_help_head[] =
    "usage: cellmap explore FILE.cmdb [SCRIPT|-] [--threads T] [--mem BYTES]\n"
    "       cellmap explore FILE.cmdb [SCRIPT|-] --model NAME [--model-lib P.so] [--param k=v,...]\n"
    "                       --cell-size DX[,DY...] [--origin X,Y...] [--depth LO:HI,...]\n"
    "                       [--max-steps K] [--threads T] [--mem BYTES]\n\n"
    "Explores basins by moving a view over the state space. Each command that\n"
    "uncovers cells computes exactly those cells as new regions and joins them\n"
    "into the cluster in FILE.cmdb (clustered SCM, thesis 4.6.4); nothing is\n"
    "computed twice, and every join is saved as it happens. A new FILE is\n"
    "created from --model, --param and the lattice (--cell-size, --origin,\n"
    "default 0); an existing one (also one made by `cellmap solve --db`) goes on\n"
    "with its model, lattice and last view. Commands come from SCRIPT, from\n"
    "stdin (- or no SCRIPT), or from a prompt when stdin is a terminal. In a\n"
    "script, a bad line stops the session with exit status 1 after saving all\n"
    "done so far; at the prompt the session goes on. A script file's run is\n"
    "journaled in FILE: the same script run again after a kill (or a failed\n"
    "line) resumes that run, so its `extend auto` steps are not repeated and the\n"
    "file ends as one run would have left it; after the script's end, a run of\n"
    "it is a new run.\n\n"
    "  --depth LO:HI,...  models of more than two dimensions: the ranges of\n"
    "                     dimensions 3.. that every view computes (default: the\n"
    "                     model's example region)\n"
    "  --max-steps K      re-step while the image stays in its own cell (default 1)\n"
    "  --threads T        OpenMP threads (default: all cores)\n"
    "  --mem BYTES        bound the cell arrays held in memory (regions are paged; one\n"
    "                     step computes at most BYTES / 12 new cells); default: an\n"
    "                     eighth of the machine's memory, 16M..128M\n\n"
    "commands (one per line, # starts a comment):\n";

typedef struct explore_args {
    session_options o;
    const char *script;
} explore_args;

static int parse_explore(cli *c, explore_args *a)
{
    int err = 0;
    session_options *o = &a->o;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(explore_help_head, stdout);
            fputs(session_help, stdout);
            return -1;
        } else if (session_opts_take(c, o, &err)) {
        } else if ((c->opt[0] != '-' || strcmp(c->opt, "-") == 0) && !o->path) {
            o->path = c->opt;
        } else if ((c->opt[0] != '-' || strcmp(c->opt, "-") == 0) && !a->script) {
            a->script = c->opt;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && !o->path)
        err = cli_usage_error(c, "which file? usage: cellmap explore FILE.cmdb [SCRIPT|-]");
    if (!err && !o->mo.name && (o->mo.n_texts || o->depth_text))
        err = cli_usage_error(c, "--param and --depth describe a new file; add --model NAME");
    return err;
}

/* Runs the lines of f; a bad line stops the session (exit 1). */
static int run_script(explore *e, FILE *f, const char *name)
{
    char line[8192], msg[1024];
    for (long lineno = 1; !e->quit && fgets(line, sizeof line, f); lineno++) {
        e->s.line = lineno;
        if (!strchr(line, '\n') && !feof(f)) {
            fprintf(stderr, "%s:%ld: the line is longer than %zu characters\n", name, lineno,
                    sizeof line - 2);
            return EXIT_FAIL;
        }
        if (explore_exec(e, line, msg, sizeof msg) != CM_OK) {
            fprintf(stderr, "%s:%ld: %s\n", name, lineno, msg);
            return EXIT_FAIL;
        }
    }
    if (ferror(f)) {
        fprintf(stderr, "cellmap explore: cannot read %s\n", name);
        return EXIT_FAIL;
    }
    return EXIT_OK;
}

/* The prompt: errors are reported and the session goes on. */
static int run_prompt(explore *e)
{
    char msg[1024];
    printf("cellmap explore %s: type help for the commands, quit to end\n", e->s.path);
    for (long lineno = 1; !e->quit; lineno++) {
        char *line = readline("explore> ");
        if (!line)
            break; /* end of input */
        if (line[strspn(line, " \t")])
            add_history(line);
        if (explore_exec(e, line, msg, sizeof msg) != CM_OK)
            fprintf(stderr, "line %ld: %s\n", lineno, msg);
        free(line);
    }
    return EXIT_OK;
}

/* A script file's run, journaled in the file (session_journal_begin): a
 * run of the same script that was killed is resumed without repeating
 * its extensions. A pipe is not journaled (it cannot be read twice). */
static int run_journaled(explore *e, const char *script, FILE *f)
{
    char hash[24], msg[1024];
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0 || !S_ISREG(sb.st_mode))
        return run_script(e, f, script);
    cm_status st = cm_file_hash(script, hash, msg, sizeof msg);
    const uint64_t h = strtoull(hash, NULL, 16);
    if (st == CM_OK)
        st = explore_journal_begin(e, h ? h : 1, msg, sizeof msg);
    if (st != CM_OK) {
        fprintf(stderr, "cellmap explore: %s\n", msg);
        return EXIT_FAIL;
    }
    int rc = run_script(e, f, script);
    if (rc == EXIT_OK && session_journal_end(&e->s, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap explore: %s\n", msg);
        rc = EXIT_FAIL;
    }
    return rc;
}

/* The session's input: the script file (opened before the session, so
 * that a missing one makes no file), standard input or the prompt. */
static int run_input(explore *e, const char *script, FILE *f)
{
    if (f)
        return run_journaled(e, script, f);
    if (!script && isatty(STDIN_FILENO))
        return run_prompt(e);
    return run_script(e, stdin, "stdin");
}

int cmd_explore(int argc, char **argv)
{
    cli c = {"explore", argc, argv, 0, NULL, NULL};
    session_keep_freed(); /* view after view */
    explore_args a;
    char command[4096], msg[1024];
    memset(&a, 0, sizeof a);
    int rc = parse_explore(&c, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    join_argv(argc + 1, argv - 1, command, sizeof command);
    a.o.command = command;
    FILE *f = NULL;
    if (a.script && strcmp(a.script, "-") != 0 && !(f = fopen(a.script, "r"))) {
        fprintf(stderr, "cellmap explore: cannot open the script %s: %s (check the path)\n",
                a.script, strerror(errno));
        return EXIT_USAGE;
    }
    /* a script is a file or a pipe (as <(...) gives); not a directory or a device */
    struct stat sb;
    if (f && fstat(fileno(f), &sb) == 0 && !S_ISREG(sb.st_mode) && !S_ISFIFO(sb.st_mode) &&
        !S_ISSOCK(sb.st_mode)) {
        fprintf(stderr, "cellmap explore: the script %s is %s; give a file of explore commands "
                        "(or - for standard input)\n",
                a.script, S_ISDIR(sb.st_mode) ? "a directory" : "a device");
        fclose(f);
        return EXIT_USAGE;
    }
    explore e;
    rc = explore_open(&e, &a.o, stdout);
    if (rc == EXIT_OK)
        rc = run_input(&e, a.script, f);
    if (f)
        fclose(f);
    /* what the session did is saved in any case */
    if (explore_close(&e, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap explore: %s\n", msg);
        rc = EXIT_FAIL;
    }
    return rc;
}
