/* lib/serve.c - the atlas over HTTP (lib/serve.h). */
#include "lib/serve.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <math.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "lib/json.h"
#include "lib/parse.h"
#include "lib/serve_page.h"

#ifndef CELLMAP_LEAFLET_DIR
#define CELLMAP_LEAFLET_DIR "/usr/share/javascript/leaflet"
#endif

/* Bytes of a connection's memory pool (libmicrohttpd's default is 32 KiB):
 * a request's line, headers and query arguments live in it. */
enum { CONNECTION_MEMORY = 256 * 1024 };

/* The most overlays one request lists (as many as a figure draws). */
enum { OVERLAYS_MAX = 4096 };

struct server {
    struct MHD_Daemon *daemon;
};

/* ---- answers ------------------------------------------------------------- */

/* Queues response r (NULL: none could be made) with its headers. */
static enum MHD_Result queue(struct MHD_Connection *conn, unsigned code, const char *type,
                             struct MHD_Response *r)
{
    if (!r)
        return MHD_NO;
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    if (code == MHD_HTTP_METHOD_NOT_ALLOWED)
        MHD_add_response_header(r, MHD_HTTP_HEADER_ALLOW, "GET, HEAD");
    const enum MHD_Result ok = MHD_queue_response(conn, code, r);
    MHD_destroy_response(r);
    return ok;
}

/* body (size bytes, malloc'd: the answer frees it) as the answer. */
static enum MHD_Result answer(struct MHD_Connection *conn, unsigned code, const char *type,
                              void *body, size_t size)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(size, body, MHD_RESPMEM_MUST_FREE);
    if (!r)
        free(body);
    return queue(conn, code, type, r);
}

/* The regular file open at fd as a 200 answer, sent from the file (the
 * answer closes fd); false (fd closed) if it is not one. */
static bool answer_file(struct MHD_Connection *conn, int fd, const char *type,
                        enum MHD_Result *result)
{
    struct stat sb;
    struct MHD_Response *r = fd >= 0 && fstat(fd, &sb) == 0 && S_ISREG(sb.st_mode)
                                 ? MHD_create_response_from_fd((size_t)sb.st_size, fd)
                                 : NULL;
    if (!r) {
        if (fd >= 0)
            close(fd);
        return false;
    }
    *result = queue(conn, MHD_HTTP_OK, type, r);
    return true;
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
    cm_box regions;
    cm_cluster_bounds(&s->c, &regions);
    session_slice_box(s, box);
    for (int d = 0; d < 2; d++) {
        box->lo[d] = s->c.nregions ? regions.lo[d] : 0;
        box->hi[d] = s->c.nregions ? regions.hi[d] : ATLAS_TILE;
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
    json_int(&j, "max_level", atlas_max_level(a));
    json_int(&j, "max_zoom", atlas_max_level(a) + 2);
    json_bool(&j, "computes", a->compute);
    json_uint(&j, "regions", s->c.nregions);
    json_uint(&j, "generation", atlas_generation(a));
    json_array(&j, "legend");
    for (uint32_t k = 0; k < n; k++) {
        json_object(&j, NULL);
        json_int(&j, "label", keys[k].label);
        json_str(&j, "name", keys[k].name);
        json_colour(&j, "colour", keys[k].colour);
        if (keys[k].label > 0)
            json_nums(&j, "centre", keys[k].centre, s->dim);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_end(&j);
    free(keys);
    return CM_OK;
}

typedef struct cell_query {
    double x, y;
    int zoom, steps;
} cell_query;

/* /cell: the cell at x, y and its orbit. */
static cm_status fill_cell(atlas *a, FILE *f, const void *arg, char *msg, size_t msg_size)
{
    const cell_query *q = arg;
    atlas_point p;
    const cm_status st = atlas_point_query(a, q->x, q->y, q->zoom, q->steps, &p, msg, msg_size);
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
    json_str(&j, "name", p.name);
    json_colour(&j, "colour", p.colour);
    json_int(&j, "level", p.level);
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
    for (; *s >= '0' && *s <= '9' && digits < 18; s++, digits++)
        x = x * 10 + (*s - '0');
    if (digits == 0 || (*s >= '0' && *s <= '9')) /* none, or a 19th */
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
    if (z < ATLAS_MIN_ZOOM || z > atlas_max_level(a)) { /* before it is an int */
        snprintf(msg, sizeof msg, "zoom %lld: tiles are drawn at zoom %d..%d", (long long)z,
                 ATLAS_MIN_ZOOM, atlas_max_level(a));
        return answer_text(conn, MHD_HTTP_BAD_REQUEST, msg);
    }
    const char *layer = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "layer");
    const bool steps = layer && strcmp(layer, "steps") == 0;
    if (layer && !steps && strcmp(layer, "basins") != 0)
        return answer_text(conn, MHD_HTTP_BAD_REQUEST, "a tile's layer is basins or steps");
    atlas_tile t;
    const cm_status st = atlas_tile_png(a, (int)z, x, y, steps ? ATLAS_STEPS : ATLAS_BASINS, &t,
                                        msg, sizeof msg);
    if (st != CM_OK)
        return answer_text(conn, status_code(st), msg);
    return answer(conn, MHD_HTTP_OK, "image/png", t.png, t.size);
}

/* A finite number, all of text (NULL: a parameter not given). */
static bool parse_number(const char *text, double *v) { return text && parse_double(text, v); }

/* A whole number lo..hi, all of text. */
static bool parse_whole(const char *text, int lo, int hi, int *v)
{
    double d;
    if (!parse_number(text, &d) || d != floor(d) || d < lo || d > hi)
        return false;
    *v = (int)d;
    return true;
}

static enum MHD_Result answer_cell(struct MHD_Connection *conn, atlas *a)
{
    cell_query q = {0, 0, 0, 100};
    const char *x = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "x");
    const char *y = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "y");
    const char *steps = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "steps");
    const char *zoom = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "zoom");
    char msg[128];
    if (!parse_number(x, &q.x) || !parse_number(y, &q.y))
        return answer_text(conn, MHD_HTTP_BAD_REQUEST,
                           "/cell needs x and y, finite numbers: "
                           "/cell?x=X&y=Y[&zoom=Z][&steps=K]");
    if (steps && !parse_whole(steps, 0, ATLAS_ORBIT_MAX, &q.steps)) {
        snprintf(msg, sizeof msg, "steps is a whole number of images, 0..%d", ATLAS_ORBIT_MAX);
        return answer_text(conn, MHD_HTTP_BAD_REQUEST, msg);
    }
    if (zoom && !parse_whole(zoom, ATLAS_MIN_ZOOM, 64, &q.zoom)) {
        snprintf(msg, sizeof msg, "zoom is a whole number, %d..64", ATLAS_MIN_ZOOM);
        return answer_text(conn, MHD_HTTP_BAD_REQUEST, msg);
    }
    return answer_json(conn, a, fill_cell, &q);
}

/* The rectangle x0:x1,y0:y1 of a request into lo, hi; false if it has none. */
static bool take_rectangle(struct MHD_Connection *conn, double lo[2], double hi[2])
{
    const char *names[] = {"x0", "x1", "y0", "y1"};
    double *at[] = {&lo[0], &hi[0], &lo[1], &hi[1]};
    for (int k = 0; k < 4; k++)
        if (!parse_number(MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, names[k]),
                          at[k]))
            return false;
    return lo[0] < hi[0] && lo[1] < hi[1];
}

static const char *const overlay_names[CM_OVERLAY_KINDS] = {
    "switching line", "unstable manifold", "stable manifold", "sticking zone",
    "regular fixed point", "virtual fixed point", "repeller", "escape", "collision",
    "higher collision"};

/* /overlays: what the model draws over the rectangle, as JSON. */
static cm_status fill_overlays(atlas *a, FILE *f, const void *arg, char *msg, size_t msg_size)
{
    const double *r = arg; /* lo[2], hi[2] */
    cm_overlay *items = malloc(OVERLAYS_MAX * sizeof *items);
    if (!items)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the overlays");
    cm_overlay_list list = {items, OVERLAYS_MAX, 0, false};
    atlas_overlays(a, r, r + 2, &list);
    json j;
    json_begin(&j, f, "serve-overlays");
    json_bool(&j, "truncated", list.truncated);
    json_array(&j, "overlays");
    for (size_t k = 0; k < list.count; k++) {
        const int kind = items[k].kind;
        json_object(&j, NULL);
        json_str(&j, "kind", kind >= 0 && kind < CM_OVERLAY_KINDS ? overlay_names[kind] : "other");
        json_nums(&j, "a", items[k].a, 2);
        json_nums(&j, "b", items[k].b, 2);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_end(&j);
    free(items);
    return CM_OK;
}

static enum MHD_Result answer_overlays(struct MHD_Connection *conn, atlas *a)
{
    double r[4];
    if (!take_rectangle(conn, r, r + 2))
        return answer_text(conn, MHD_HTTP_BAD_REQUEST,
                           "/overlays needs x0 < x1, y0 < y1, finite numbers");
    return answer_json(conn, a, fill_overlays, r);
}

/* The figure `render` draws of the rectangle x0:x1,y0:y1 (w x h pixels,
 * default 1000 x 800), as a PNG or SVG file to download: drawn into a
 * temporary file (its directory TMPDIR, else /tmp), removed once open, and
 * sent from it. */
static enum MHD_Result answer_figure(struct MHD_Connection *conn, atlas *a, bool svg)
{
    double lo[2], hi[2];
    if (!take_rectangle(conn, lo, hi))
        return answer_text(conn, MHD_HTTP_BAD_REQUEST,
                           "a figure needs x0 < x1, y0 < y1, finite numbers: "
                           "/figure.png?x0=X0&x1=X1&y0=Y0&y1=Y1[&w=W&h=H]");
    png_opts po;
    memset(&po, 0, sizeof po);
    po.n_labels = a->nnames < PNG_LABELS_MAX ? a->nnames : PNG_LABELS_MAX;
    memcpy(po.labels, a->names, (size_t)po.n_labels * sizeof *po.labels);
    po.default_layers = all_layers;
    po.by = BY_ATTRACTORS;
    po.width = 1000;
    po.height = 800;
    const char *w = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "w");
    const char *h = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "h");
    if ((w && !parse_whole(w, 64, 4096, &po.width)) || (h && !parse_whole(h, 64, 4096, &po.height)))
        return answer_text(conn, MHD_HTTP_BAD_REQUEST, "w and h are pixels, 64..4096");
    const char *tmp = getenv("TMPDIR");
    char path[4096], msg[1024];
    snprintf(path, sizeof path, "%s/cellmap-serve-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    const int fd = mkstemp(path);
    if (fd < 0)
        return answer_text(conn, MHD_HTTP_INTERNAL_SERVER_ERROR,
                           "cannot make a temporary file for the figure (TMPDIR)");
    close(fd);
    *(svg ? &po.svg : &po.path) = path;
    const cm_status st = session_figure(a->s, &po, lo, hi, msg, sizeof msg);
    const int figure = st == CM_OK ? open(path, O_RDONLY) : -1;
    unlink(path); /* the open file stays until it is sent */
    enum MHD_Result result;
    if (st != CM_OK)
        return answer_text(conn, status_code(st), msg);
    return answer_file(conn, figure, svg ? "image/svg+xml" : "image/png", &result)
               ? result
               : answer_text(conn, MHD_HTTP_INTERNAL_SERVER_ERROR, "cannot read the figure back");
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
        enum MHD_Result result;
        return answer_file(conn, open(path, O_RDONLY), leaflet_files[i][1], &result)
                   ? result
                   : answer_text(conn, MHD_HTTP_INTERNAL_SERVER_ERROR,
                                 "Leaflet's files are missing: install Debian's libjs-leaflet");
    }
    return answer_text(conn, MHD_HTTP_NOT_FOUND, "no such file of Leaflet's");
}

static enum MHD_Result answer_page(struct MHD_Connection *conn)
{
    size_t size = 0;
    for (int k = 0; serve_page[k]; k++)
        size += strlen(serve_page[k]);
    char *body = malloc(size + 1), *end = body;
    if (!body)
        return MHD_NO;
    for (int k = 0; serve_page[k]; k++)
        end = stpcpy(end, serve_page[k]);
    return answer(conn, MHD_HTTP_OK, "text/html; charset=utf-8", body, size);
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
    if (strcmp(url, "/overlays") == 0)
        return answer_overlays(conn, a);
    if (strcmp(url, "/figure.png") == 0 || strcmp(url, "/figure.svg") == 0)
        return answer_figure(conn, a, strcmp(url, "/figure.svg") == 0);
    if (starts_with(url, "/tiles/"))
        return answer_tile(conn, a, url);
    if (starts_with(url, "/leaflet/"))
        return answer_leaflet(conn, url + strlen("/leaflet/"));
    return answer_text(conn, MHD_HTTP_NOT_FOUND,
                       "no such page: /, /info, /tiles/Z/X/Y.png, /cell?x=X&y=Y, /overlays, "
                       "/figure.png, /figure.svg and /leaflet/... are served");
}

/* The address to listen on, from --bind (IPv4 or IPv6) and --port. */
static bool listen_address(const char *bind, int port, struct sockaddr_storage *addr, bool *v6)
{
    memset(addr, 0, sizeof *addr);
    struct sockaddr_in *in4 = (struct sockaddr_in *)addr;
    struct sockaddr_in6 *in6 = (struct sockaddr_in6 *)addr;
    *v6 = strchr(bind, ':') != NULL;
    if (*v6) {
        in6->sin6_family = AF_INET6;
        in6->sin6_port = htons((uint16_t)port);
        return inet_pton(AF_INET6, bind, &in6->sin6_addr) == 1;
    }
    in4->sin_family = AF_INET;
    in4->sin_port = htons((uint16_t)port);
    return inet_pton(AF_INET, bind, &in4->sin_addr) == 1;
}



/* ---- the server ---------------------------------------------------------- */

bool serve_address_valid(const char *bind)
{
    struct sockaddr_storage addr;
    bool v6;
    return listen_address(bind, 0, &addr, &v6);
}

bool serve_is_loopback(const char *bind)
{
    return starts_with(bind, "127.") || strcmp(bind, "::1") == 0;
}

cm_status serve_start(atlas *a, const char *bind, int port, server **out, int *bound,
                      char *msg, size_t msg_size)
{
    struct sockaddr_storage addr;
    bool v6;
    *out = NULL;
    if (!listen_address(bind, port, &addr, &v6))
        return cm_fail(CM_EINVAL, msg, msg_size, "%s is not an IPv4 or IPv6 address", bind);
    server *s = calloc(1, sizeof *s);
    if (!s)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the server");
    s->daemon = MHD_start_daemon(
        MHD_USE_AUTO_INTERNAL_THREAD | (v6 ? MHD_USE_IPv6 : 0), (uint16_t)port, NULL, NULL,
        on_request, a, MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
        MHD_OPTION_CONNECTION_LIMIT, (unsigned)256, MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)60,
        MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)CONNECTION_MEMORY,
        MHD_OPTION_LISTEN_BACKLOG_SIZE, (unsigned)256, MHD_OPTION_END);
    if (!s->daemon) {
        free(s);
        return cm_fail(CM_EIO, msg, msg_size,
                       "cannot listen on %s port %d (in use? choose another port, or 0 for any "
                       "free one)",
                       bind, port);
    }
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(s->daemon, MHD_DAEMON_INFO_BIND_PORT);
    *bound = info ? info->port : port;
    *out = s;
    return CM_OK;
}

void serve_stop(server *s)
{
    if (!s)
        return;
    MHD_stop_daemon(s->daemon);
    free(s);
}
