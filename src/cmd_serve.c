/* cellmap serve: the basin atlas of a cluster database in a browser
 * (lib/atlas.h over an explore session, HTTP by libmicrohttpd). Built as
 * its own program, cellmap-serve, which `cellmap serve` runs, so that the
 * other commands do not load the HTTP library and its TLS stack at start.
 *
 * One thread answers the requests, one after another: the session is used
 * by one thread at a time, and every computation it makes is joined and
 * committed before its tile is answered, so SIGINT or SIGTERM at any point
 * leaves the file as the last answered request left it. */
#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/atlas.h"
#include "lib/json.h"
#include "src/args.h"
#include "src/commands.h"
#include "src/serve_page.h"

#ifndef CELLMAP_LEAFLET_DIR
#define CELLMAP_LEAFLET_DIR "/usr/share/javascript/leaflet"
#endif

static const char serve_help[] =
    "usage: cellmap serve FILE.cmdb [--port N] [--bind ADDR] [--read-only] [--tile-cells N]\n"
    "                     [--threads T] [--mem BYTES]\n"
    "       cellmap serve FILE.cmdb --model NAME [--model-lib P.so] [--param k=v,...]\n"
    "                     --cell-size DX[,DY...] [--origin X,Y...] [--depth LO:HI,...]\n"
    "                     [--max-steps K] [... as above]\n\n"
    "Serves the basin atlas of FILE.cmdb to a browser: open the address it prints.\n"
    "The page (Leaflet) pans and zooms a map of the basins in state coordinates,\n"
    "one pixel per cell at zoom 0 and up to 8x8 cells a pixel zoomed out; a click\n"
    "shows the cell, its group, step number and attractor, and draws its true\n"
    "orbit. Tiles over cells the cluster lacks compute them first, as an explore\n"
    "pan would (new regions, joined and committed to FILE), unless --read-only.\n"
    "A new FILE is made from --model and the lattice, as `cellmap explore` makes\n"
    "one. The file is in use while it serves (explore or solve --resume on it are\n"
    "refused); SIGINT or SIGTERM (Ctrl-C) ends it with the file consistent.\n\n"
    "  --port N         TCP port (default 8080; 0: any free one, printed)\n"
    "  --bind ADDR      the address to listen on (default 127.0.0.1: this machine\n"
    "                   only; another address exposes the file to the network)\n"
    "  --read-only      never compute: tiles draw what the file holds\n"
    "  --tile-cells N   the most cells one tile computes (default 1048576)\n"
    "  --threads T      OpenMP threads (default: all cores)\n"
    "  --mem BYTES      bound the cell arrays held in memory (as explore)\n\n"
    "Requests: / (the page), /info (JSON: lattice, view, legend), /tiles/Z/X/Y.png\n"
    "(256x256, zoom -3..0; docs/serve.md gives the scheme), /cell?x=X&y=Y[&steps=K]\n"
    "(JSON: the cell and its orbit of K images, default 100, at most 10000),\n"
    "/leaflet/... (Leaflet's files from " CELLMAP_LEAFLET_DIR ").\n";

typedef struct serve_args {
    session_options o;
    int port;
    const char *bind;
    bool read_only;
    uint64_t tile_cells;
} serve_args;

/* The address to listen on, from --bind (IPv4 or IPv6) and --port. */
static bool listen_address(const serve_args *a, struct sockaddr_storage *addr, bool *v6)
{
    memset(addr, 0, sizeof *addr);
    struct sockaddr_in *in4 = (struct sockaddr_in *)addr;
    struct sockaddr_in6 *in6 = (struct sockaddr_in6 *)addr;
    *v6 = strchr(a->bind, ':') != NULL;
    if (*v6) {
        in6->sin6_family = AF_INET6;
        in6->sin6_port = htons((uint16_t)a->port);
        return inet_pton(AF_INET6, a->bind, &in6->sin6_addr) == 1;
    }
    in4->sin_family = AF_INET;
    in4->sin_port = htons((uint16_t)a->port);
    return inet_pton(AF_INET, a->bind, &in4->sin_addr) == 1;
}

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
        } else if (model_opts_take(c, &o->mo, &err)) {
        } else if (cli_is(c, "--cell-size", true, &err)) {
            if (c->value && !parse_doubles(c->value, o->cell_size, &o->n_cell_size, CM_MAX_DIM))
                err = cli_usage_error(c, "--cell-size: '%s' is not DX[,DY...]", c->value);
        } else if (cli_is(c, "--origin", true, &err)) {
            if (c->value && !parse_doubles(c->value, o->origin, &o->n_origin, CM_MAX_DIM))
                err = cli_usage_error(c, "--origin: '%s' is not X[,Y...]", c->value);
        } else if (cli_is(c, "--depth", true, &err)) {
            o->depth_text = c->value;
        } else if (cli_take_int(c, "--max-steps", 1, MAX_STEPS_LIMIT, &o->max_steps, &err)) {
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &o->threads, &err)) {
        } else if (cli_take_mem(c, &o->mem, &err)) {
        } else if (cli_take_int(c, "--port", 0, 65535, &a->port, &err)) {
        } else if (cli_take_int(c, "--tile-cells", 1, 1 << 26, &tile_cells, &err)) {
        } else if (cli_is(c, "--bind", true, &err)) {
            a->bind = c->value;
        } else if (cli_is(c, "--read-only", false, &err)) {
            a->read_only = true;
        } else if (c->opt[0] != '-' && !o->path) {
            o->path = c->opt;
        } else {
            err = cli_stray(c);
        }
    }
    a->tile_cells = (uint64_t)tile_cells;
    struct sockaddr_storage addr;
    bool v6;
    if (!err && !listen_address(a, &addr, &v6))
        err = cli_usage_error(c, "--bind %s is not an IPv4 or IPv6 address", a->bind);
    if (!err && !o->path)
        err = cli_usage_error(c, "which file? usage: cellmap serve FILE.cmdb [--port N]");
    if (!err && !o->mo.name && (o->mo.n_texts || o->depth_text))
        err = cli_usage_error(c, "--param and --depth describe a new file; add --model NAME");
    return err;
}

/* ---- answers ------------------------------------------------------------ */

static enum MHD_Result answer(struct MHD_Connection *conn, unsigned code, const char *type,
                              void *body, size_t size)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(size, body, MHD_RESPMEM_MUST_FREE);
    if (!r) {
        free(body);
        return MHD_NO;
    }
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    if (code == MHD_HTTP_METHOD_NOT_ALLOWED)
        MHD_add_response_header(r, MHD_HTTP_HEADER_ALLOW, "GET, HEAD");
    const enum MHD_Result ok = MHD_queue_response(conn, code, r);
    MHD_destroy_response(r);
    return ok;
}

/* A plain-text answer: "cellmap serve: text\n". */
static enum MHD_Result answer_text(struct MHD_Connection *conn, unsigned code, const char *text)
{
    const size_t size = strlen(text) + 32;
    char *body = malloc(size);
    if (!body)
        return MHD_NO;
    const int n = snprintf(body, size, "cellmap serve: %s\n", text);
    return answer(conn, code, "text/plain; charset=utf-8", body, (size_t)n);
}

/* The HTTP status of a failed call: the request's fault or the server's. */
static unsigned status_code(cm_status st)
{
    return st == CM_EINVAL || st == CM_ETOOBIG ? MHD_HTTP_BAD_REQUEST
                                               : MHD_HTTP_INTERNAL_SERVER_ERROR;
}

/* A JSON document written by fill into memory, answered. */
typedef cm_status (*json_fill)(atlas *a, FILE *f, const void *arg, char *msg,
                               size_t msg_size);

static enum MHD_Result answer_json(struct MHD_Connection *conn, atlas *a, json_fill fill,
                                   const void *arg)
{
    char *body = NULL, msg[1024];
    size_t size = 0;
    FILE *f = open_memstream(&body, &size);
    if (!f)
        return answer_text(conn, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
    const cm_status st = fill(a, f, arg, msg, sizeof msg);
    const bool written = fclose(f) == 0;
    if (st != CM_OK || !written) {
        free(body);
        return answer_text(conn, st != CM_OK ? status_code(st) : MHD_HTTP_INTERNAL_SERVER_ERROR,
                           st != CM_OK ? msg : "out of memory for the answer");
    }
    return answer(conn, MHD_HTTP_OK, "application/json", body, size);
}

static void json_colour(json *j, const char *key, cm_rgb c)
{
    char text[8];
    snprintf(text, sizeof text, "#%02x%02x%02x", c.r, c.g, c.b);
    json_str(j, key, text);
}

/* The cells the page shows first: the session's view, else the
 * cluster's regions, else a tile's cells at the origin. */
static void first_view(const session *s, cm_box *box)
{
    if (s->have_view) {
        session_shown_cells(s, box);
        return;
    }
    box->dim = s->dim;
    for (int d = 0; d < s->dim; d++) {
        box->lo[d] = d < 2 ? 0 : s->slice[d];
        box->hi[d] = d < 2 ? ATLAS_TILE : s->slice[d] + 1;
    }
    for (uint32_t k = 0; k < s->c.nregions; k++) {
        const cm_box *r = &s->c.regions[k].r.box;
        for (int d = 0; d < 2; d++) {
            box->lo[d] = k == 0 || r->lo[d] < box->lo[d] ? r->lo[d] : box->lo[d];
            box->hi[d] = k == 0 || r->hi[d] > box->hi[d] ? r->hi[d] : box->hi[d];
        }
    }
}

/* /info: the model, lattice, first view, zooms and legend. */
static cm_status fill_info(atlas *a, FILE *f, const void *arg, char *msg, size_t msg_size)
{
    (void)arg;
    const session *s = a->s;
    atlas_key *keys = NULL;
    uint32_t n = 0;
    const cm_status st = atlas_legend(a, &keys, &n, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_box view;
    first_view(s, &view);
    json j;
    json_begin(&j, f, "serve-info");
    json_model(&j, &s->model);
    json_lattice(&j, &s->c.lat);
    json_box(&j, "view", &s->c.lat, &view);
    json_int(&j, "tile", ATLAS_TILE);
    json_int(&j, "min_zoom", ATLAS_MIN_ZOOM);
    json_int(&j, "max_zoom", 4);
    json_bool(&j, "computes", a->compute);
    json_uint(&j, "regions", s->c.nregions);
    json_array(&j, "legend");
    for (uint32_t k = 0; k < n; k++) {
        json_object(&j, NULL);
        json_int(&j, "label", keys[k].label);
        json_str(&j, "name", keys[k].name);
        json_colour(&j, "colour", keys[k].colour);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_end(&j);
    free(keys);
    return CM_OK;
}

typedef struct cell_query {
    double x, y;
    int steps;
} cell_query;

/* /cell: the cell at x, y and its orbit. */
static cm_status fill_cell(atlas *a, FILE *f, const void *arg, char *msg, size_t msg_size)
{
    const cell_query *q = arg;
    atlas_point p;
    const cm_status st = atlas_point_query(a, q->x, q->y, q->steps, &p, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int dim = a->s->dim;
    json j;
    json_begin(&j, f, "serve-cell");
    json_array(&j, "cell");
    for (int d = 0; d < dim; d++)
        json_int(&j, NULL, p.cell[d]);
    json_array_end(&j);
    json_nums(&j, "centre", p.centre, dim);
    json_bool(&j, "computed", p.computed);
    json_uint(&j, "group", p.group);
    json_uint(&j, "step", p.step);
    json_int(&j, "label", p.label);
    json_array(&j, "orbit");
    for (int k = 0; k < p.norbit; k++)
        json_nums(&j, NULL, p.orbit + (size_t)k * (size_t)dim, dim);
    json_array_end(&j);
    json_end(&j);
    atlas_point_free(&p);
    return CM_OK;
}

/* ---- requests ----------------------------------------------------------- */

/* An integer of at most 18 digits, optionally signed, at *p; advances. */
static bool take_int(const char **p, int64_t *v)
{
    const char *s = *p;
    const bool negative = *s == '-';
    s += negative;
    int64_t x = 0;
    int digits = 0;
    for (; *s >= '0' && *s <= '9' && digits < 19; s++, digits++)
        x = x * 10 + (*s - '0');
    if (digits == 0 || digits > 18)
        return false;
    *v = negative ? -x : x;
    *p = s;
    return true;
}

/* "/tiles/Z/X/Y.png" into z, x, y. */
static bool parse_tile(const char *url, int64_t *z, int64_t *x, int64_t *y)
{
    const char *p = url + strlen("/tiles/");
    return take_int(&p, z) && *p++ == '/' && take_int(&p, x) && *p++ == '/' &&
           take_int(&p, y) && strcmp(p, ".png") == 0;
}

static enum MHD_Result answer_tile(struct MHD_Connection *conn, atlas *a, const char *url)
{
    int64_t z, x, y;
    char msg[1024];
    if (!parse_tile(url, &z, &x, &y))
        return answer_text(conn, MHD_HTTP_BAD_REQUEST,
                           "a tile is /tiles/Z/X/Y.png with integers Z, X and Y");
    if (z < ATLAS_MIN_ZOOM || z > 0) { /* before it is an int */
        snprintf(msg, sizeof msg, "zoom %lld: tiles are drawn at zoom %d..0", (long long)z,
                 ATLAS_MIN_ZOOM);
        return answer_text(conn, MHD_HTTP_BAD_REQUEST, msg);
    }
    atlas_tile t;
    const cm_status st = atlas_tile_png(a, (int)z, x, y, &t, msg, sizeof msg);
    if (st != CM_OK)
        return answer_text(conn, status_code(st), msg);
    return answer(conn, MHD_HTTP_OK, "image/png", t.png, t.size);
}

/* A finite number, all of text. */
static bool parse_number(const char *text, double *v)
{
    char *end = NULL;
    if (!text || !*text)
        return false;
    errno = 0;
    *v = strtod(text, &end);
    return *end == '\0' && errno == 0 && isfinite(*v);
}

static enum MHD_Result answer_cell(struct MHD_Connection *conn, atlas *a)
{
    cell_query q = {0, 0, 100};
    const char *x = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "x");
    const char *y = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "y");
    const char *steps = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "steps");
    double k = q.steps;
    if (!parse_number(x, &q.x) || !parse_number(y, &q.y))
        return answer_text(conn, MHD_HTTP_BAD_REQUEST,
                           "/cell needs x and y, finite numbers: /cell?x=X&y=Y[&steps=K]");
    if (steps && (!parse_number(steps, &k) || k != floor(k) || k < 0 || k > ATLAS_ORBIT_MAX)) {
        char msg[128];
        snprintf(msg, sizeof msg, "steps is a whole number of images, 0..%d", ATLAS_ORBIT_MAX);
        return answer_text(conn, MHD_HTTP_BAD_REQUEST, msg);
    }
    q.steps = (int)k;
    return answer_json(conn, a, fill_cell, &q);
}

/* Leaflet's files, by name: nothing else of the disk is served. */
static const char *const leaflet_files[][2] = {
    {"leaflet.js", "text/javascript"},
    {"leaflet.css", "text/css"},
    {"images/layers.png", "image/png"},
    {"images/layers-2x.png", "image/png"},
    {"images/marker-icon.png", "image/png"},
    {"images/marker-icon-2x.png", "image/png"},
    {"images/marker-shadow.png", "image/png"},
};

static enum MHD_Result answer_leaflet(struct MHD_Connection *conn, const char *name)
{
    for (size_t i = 0; i < sizeof leaflet_files / sizeof *leaflet_files; i++) {
        if (strcmp(name, leaflet_files[i][0]) != 0)
            continue;
        char path[512];
        snprintf(path, sizeof path, "%s/%s", CELLMAP_LEAFLET_DIR, leaflet_files[i][0]);
        FILE *f = fopen(path, "rb");
        char *body = NULL;
        long size = -1;
        if (f && fseek(f, 0, SEEK_END) == 0 && (size = ftell(f)) >= 0 &&
            fseek(f, 0, SEEK_SET) == 0 && (body = malloc((size_t)size + 1)) &&
            fread(body, 1, (size_t)size, f) == (size_t)size) {
            fclose(f);
            return answer(conn, MHD_HTTP_OK, leaflet_files[i][1], body, (size_t)size);
        }
        if (f)
            fclose(f);
        free(body);
        return answer_text(conn, MHD_HTTP_INTERNAL_SERVER_ERROR,
                           "Leaflet's files are missing: install Debian's libjs-leaflet");
    }
    return answer_text(conn, MHD_HTTP_NOT_FOUND, "no such file of Leaflet's");
}

static enum MHD_Result answer_page(struct MHD_Connection *conn)
{
    char *body = strdup(serve_page);
    if (!body)
        return MHD_NO;
    return answer(conn, MHD_HTTP_OK, "text/html; charset=utf-8", body, strlen(body));
}

static bool starts_with(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url,
                                  const char *method, const char *version,
                                  const char *upload_data, size_t *upload_data_size,
                                  void **state)
{
    static int headers_seen;
    (void)version;
    (void)upload_data;
    atlas *a = cls;
    if (!*state) { /* the headers: answer when the request is whole */
        *state = &headers_seen;
        return MHD_YES;
    }
    if (*upload_data_size != 0) {
        *upload_data_size = 0; /* a body is not read */
        return MHD_YES;
    }
    if (strcmp(method, MHD_HTTP_METHOD_GET) != 0 && strcmp(method, MHD_HTTP_METHOD_HEAD) != 0)
        return answer_text(conn, MHD_HTTP_METHOD_NOT_ALLOWED, "only GET and HEAD are answered");
    if (strcmp(url, "/") == 0 || strcmp(url, "/index.html") == 0)
        return answer_page(conn);
    if (strcmp(url, "/info") == 0)
        return answer_json(conn, a, fill_info, NULL);
    if (strcmp(url, "/cell") == 0)
        return answer_cell(conn, a);
    if (starts_with(url, "/tiles/"))
        return answer_tile(conn, a, url);
    if (starts_with(url, "/leaflet/"))
        return answer_leaflet(conn, url + strlen("/leaflet/"));
    return answer_text(conn, MHD_HTTP_NOT_FOUND,
                       "no such page: /, /info, /tiles/Z/X/Y.png, /cell?x=X&y=Y are served");
}

/* ---- the server ---------------------------------------------------------- */

static bool is_loopback(const char *bind)
{
    return starts_with(bind, "127.") || strcmp(bind, "::1") == 0;
}

/* Serves until SIGINT or SIGTERM (blocked here, so that every thread
 * started after leaves them to sigwait). */
static int run_server(const serve_args *a, atlas *at)
{
    struct sockaddr_storage addr;
    bool v6;
    listen_address(a, &addr, &v6); /* checked by parse_serve */
    sigset_t stop;
    sigemptyset(&stop);
    sigaddset(&stop, SIGINT);
    sigaddset(&stop, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stop, NULL);
    signal(SIGPIPE, SIG_IGN);
    struct MHD_Daemon *d = MHD_start_daemon(
        MHD_USE_AUTO_INTERNAL_THREAD | (v6 ? MHD_USE_IPv6 : 0), (uint16_t)a->port, NULL, NULL,
        on_request, at, MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
        MHD_OPTION_CONNECTION_LIMIT, (unsigned)256, MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)60,
        MHD_OPTION_LISTEN_BACKLOG_SIZE, (unsigned)256, MHD_OPTION_END);
    if (!d) {
        fprintf(stderr, "cellmap serve: cannot listen on %s port %d (in use? choose another with "
                        "--port, or 0 for any free one)\n",
                a->bind, a->port);
        return EXIT_FAIL;
    }
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(d, MHD_DAEMON_INFO_BIND_PORT);
    const int port = info ? info->port : a->port;
    if (!is_loopback(a->bind))
        fprintf(stderr, "cellmap serve: warning: listening on %s: anyone who reaches this "
                        "machine can read%s the file\n",
                a->bind, at->compute ? " and grow" : "");
    printf("cellmap serve: %s at http://%s%s%s:%d/ (Ctrl-C ends)\n", at->s->path, v6 ? "[" : "",
           a->bind, v6 ? "]" : "", port);
    fflush(stdout);
    int sig = 0;
    sigwait(&stop, &sig);
    MHD_stop_daemon(d); /* waits for the request being answered */
    printf("cellmap serve: %s, stopped\n", sig == SIGINT ? "interrupted" : "terminated");
    return EXIT_OK;
}

int cmd_serve(int argc, char **argv)
{
    cli c = {"serve", argc, argv, 0, NULL, NULL};
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
    cm_status st = session_open(&s, &a.o, &opened, msg, sizeof msg);
    cli_said_upgrade("serve", a.o.path, opened.upgraded_from);
    if (st == CM_OK && s.dim < 2) {
        snprintf(msg, sizeof msg, "the atlas draws two state coordinates; model %s has one",
                 s.model.name);
        st = CM_EINVAL;
    }
    if (st == CM_OK) {
        atlas at;
        atlas_init(&at, &s, !a.read_only,
                   a.tile_cells < s.max_new_cells ? a.tile_cells : s.max_new_cells);
        rc = run_server(&a, &at);
        atlas_free(&at);
    } else {
        fprintf(stderr, "cellmap serve: %s\n", msg);
        rc = opened.bad_options ? EXIT_USAGE : EXIT_FAIL;
    }
    if (session_close(&s, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap serve: %s\n", msg);
        rc = EXIT_FAIL;
    }
    return rc;
}
