/* cellmap serve: the basin atlas of a cluster database in a browser
 * (lib/serve.h over lib/atlas.h over an explore session). Built as its own
 * program, cellmap-serve, which `cellmap serve` runs, so that the other
 * commands do not load the HTTP library and its TLS stack at start.
 *
 * Every computation a request makes is joined and committed before its
 * tile is answered, so SIGINT or SIGTERM at any point leaves the file as
 * the last answered request left it. */
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lib/serve.h"
#include "src/args.h"
#include "src/commands.h"
#include "src/explore.h"

static const char serve_help[] =
    "usage: cellmap serve FILE.cmdb [--port N] [--bind ADDR] [--read-only] [--tile-cells N]\n"
    "                     [--labels FILE] [--threads T] [--mem BYTES]\n"
    "       cellmap serve FILE.cmdb --model NAME [--model-lib P.so] [--param k=v,...]\n"
    "                     --cell-size DX[,DY...] [--origin X,Y...] [--depth LO:HI,...]\n"
    "                     [--max-steps K] [... as above]\n\n"
    "Serves the basin atlas of FILE.cmdb to a browser: open the address it prints.\n"
    "The page (Leaflet) pans and zooms a map of the basins in state coordinates,\n"
    "one pixel per cell at zoom 0, up to 8x8 cells a pixel zoomed out, and zoomed\n"
    "in the cells of refined lattices (cells 2, 4, 8 times narrower, each a cluster\n"
    "in FILE.zoom1.cmdb, .zoom2, .zoom3 beside FILE); a click shows the cell, its\n"
    "group, step number and attractor, and draws its true orbit. Tiles over cells\n"
    "a cluster lacks compute them first, as an explore pan would (new regions,\n"
    "joined and committed), unless --read-only.\n"
    "A new FILE is made from --model and the lattice, as `cellmap explore` makes\n"
    "one. The file is in use while it serves (explore or solve --resume on it are\n"
    "refused); SIGINT or SIGTERM (Ctrl-C) ends it with the file consistent.\n\n"
    "  --port N         TCP port (default 8080; 0: any free one, printed)\n"
    "  --bind ADDR      the address to listen on (default 127.0.0.1: this machine\n"
    "                   only; another address exposes the file to the network)\n"
    "  --read-only      never compute: tiles draw what the file holds\n"
    "  --tile-cells N   the most cells one tile computes (default 1048576)\n"
    "  --labels FILE    the legend's names of attractors, as render takes them\n"
    "                   (lines 'ID TEXT', or 'I0,I1 TEXT' for the anchor cell)\n"
    "  --threads T      OpenMP threads (default: all cores)\n"
    "  --mem BYTES      bound the cell arrays held in memory (as explore)\n\n"
    "Requests: / (the page), /info (JSON: lattice, view, legend), /tiles/Z/X/Y.png\n"
    "(256x256, zoom -3..3; docs/serve.md gives the scheme),\n"
    "/cell?x=X&y=Y[&zoom=Z][&steps=K] (JSON: the cell of the level zoom Z shows,\n"
    "its label and colour, its orbit of K images, default 100, at most 10000),\n"
    "/figure.png|svg?x0=X0&x1=X1&y0=Y0&y1=Y1[&w=W&h=H] (what render --layers all\n"
    "draws of that view),\n"
    "/leaflet/... (Leaflet's files, from Debian's libjs-leaflet).\n";

typedef struct serve_args {
    session_options o;
    png_opts names; /* --labels FILE: the legend's names */
    int port;
    const char *bind;
    bool read_only;
    uint64_t tile_cells;
} serve_args;

static int parse_serve(cli *c, serve_args *a)
{
    int err = 0, tile_cells = 1 << 20;
    session_options *o = &a->o;
    a->port = 8080;
    a->bind = "127.0.0.1";
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(serve_help, stdout);
            return -1;
        } else if (session_opts_take(c, o, &err)) {
        } else if (cli_take_int(c, "--port", 0, 65535, &a->port, &err)) {
        } else if (cli_take_int(c, "--tile-cells", 1, 1 << 26, &tile_cells, &err)) {
        } else if (cli_is(c, "--bind", true, &err)) {
            a->bind = c->value;
        } else if (cli_is(c, "--read-only", false, &err)) {
            a->read_only = true;
        } else if (cli_is(c, "--labels", true, &err)) {
            char msg[1024];
            if (c->value && !png_opts_labels(c->value, &a->names, msg, sizeof msg))
                err = cli_usage_error(c, "--labels: %s", msg);
        } else if (c->opt[0] != '-' && !o->path) {
            o->path = c->opt;
        } else {
            err = cli_stray(c);
        }
    }
    a->tile_cells = (uint64_t)tile_cells;
    if (!err && !serve_address_valid(a->bind))
        err = cli_usage_error(c, "--bind %s is not an IPv4 or IPv6 address", a->bind);
    if (!err && !o->path)
        err = cli_usage_error(c, "which file? usage: cellmap serve FILE.cmdb [--port N]");
    if (!err && !o->mo.name && (o->mo.n_texts || o->depth_text))
        err = cli_usage_error(c, "--param and --depth describe a new file; add --model NAME");
    return err;
}

/* ---- the server ---------------------------------------------------------- */

/* Serves until SIGINT or SIGTERM (blocked here, so that every thread
 * started after leaves them to sigwait). */
static int run_server(const serve_args *a, atlas *at, bool *started)
{
    sigset_t stop;
    sigemptyset(&stop);
    sigaddset(&stop, SIGINT);
    sigaddset(&stop, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stop, NULL);
    signal(SIGPIPE, SIG_IGN);
    server *srv = NULL;
    int port = 0;
    char msg[1024];
    if (serve_start(at, a->bind, a->port, &srv, &port, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap serve: %s\n", msg);
        return EXIT_FAIL;
    }
    *started = true;
    const bool v6 = strchr(a->bind, ':') != NULL;
    if (!serve_is_loopback(a->bind))
        fprintf(stderr, "cellmap serve: warning: listening on %s: anyone who reaches this "
                        "machine can read%s the file\n",
                a->bind, at->compute ? " and grow" : "");
    printf("cellmap serve: %s at http://%s%s%s:%d/ (Ctrl-C ends)\n", at->s->path, v6 ? "[" : "",
           a->bind, v6 ? "]" : "", port);
    fflush(stdout);
    int sig = 0;
    sigwait(&stop, &sig);
    serve_stop(srv); /* after the request being answered */
    printf("cellmap serve: %s, stopped\n", sig == SIGINT ? "interrupted" : "terminated");
    return EXIT_OK;
}

int cmd_serve(int argc, char **argv)
{
    cli c = {"serve", argc, argv, 0, NULL, NULL};
    session_keep_freed(); /* view after view */
    serve_args a;
    char command[4096], msg[2048];
    memset(&a, 0, sizeof a);
    int rc = parse_serve(&c, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    /* argv[0] is "serve" (run by cellmap) or the program's own name */
    const size_t head = (size_t)snprintf(command, sizeof command, "cellmap serve ");
    join_argv(argc - 1, argv + 1, command + head, sizeof command - head);
    a.o.command = command;
    session s;
    session_opened opened;
    /* a file made here is removed again if serving never starts */
    const bool made = access(a.o.path, F_OK) != 0;
    bool started = false;
    cm_status st = session_open(&s, &a.o, &opened, msg, sizeof msg);
    cli_said_upgrade("serve", a.o.path, opened.upgraded_from);
    if (st == CM_OK && s.dim < 2) {
        snprintf(msg, sizeof msg, "the atlas draws two state coordinates; model %s has one",
                 s.model.name);
        st = CM_EINVAL;
    }
    if (st == CM_OK) {
        atlas at;
        atlas_init(&at, &s, &a.o, !a.read_only,
                   a.tile_cells < s.max_new_cells ? a.tile_cells : s.max_new_cells);
        at.names = a.names.labels;
        at.nnames = a.names.n_labels;
        rc = run_server(&a, &at, &started);
        if (atlas_free(&at, msg, sizeof msg) != CM_OK) {
            fprintf(stderr, "cellmap serve: %s\n", msg);
            rc = EXIT_FAIL;
        }
    } else {
        fprintf(stderr, "cellmap serve: %s\n", msg);
        rc = opened.bad_options ? EXIT_USAGE : EXIT_FAIL;
    }
    if (session_close(&s, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap serve: %s\n", msg);
        rc = EXIT_FAIL;
    }
    if (made && !started)
        unlink(a.o.path);
    return rc;
}
