/* lib/figure.c - the one basin-figure pipeline (lib/figure.h): PNG, SVG
 * and indexed PNG, by groups or by attractors. */
#include "lib/figure.h"

#include "cellmap/output.h"
#include "render/pdf.h"
#include "render/svg.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/store.h"
#include "render/figure.h"
#include "render/palette.h"
#include "render/png_out.h"
#include "render/raster.h"
#include "lib/attractor_report.h"
#include "lib/project.h"
#include "lib/outfile.h"
#include "lib/parse.h"

enum { MAX_DEFAULT_SIDE = 4096, FIGURE_SIDE = 1000 };

static const struct {
    const char *name;
    unsigned bit;
} layer_names[] = {
    {"basin", CM_LAYER_BASIN},       {"steps", CM_LAYER_STEPS}, {"attractors", CM_LAYER_ATTRACTORS},
    {"overlays", CM_LAYER_OVERLAYS}, {"axes", CM_LAYER_AXES},   {"legend", CM_LAYER_LEGEND},
    {"title", CM_LAYER_TITLE},
};

const unsigned all_layers = CM_LAYER_BASIN | CM_LAYER_ATTRACTORS | CM_LAYER_OVERLAYS |
                                   CM_LAYER_AXES | CM_LAYER_LEGEND | CM_LAYER_TITLE;

bool parse_layers(const char *s, unsigned *layers, char *bad, size_t bad_size)
{
    *layers = 0;
    while (*s) {
        const size_t n = strcspn(s, ",");
        unsigned bit = 0;
        if (n == 3 && strncmp(s, "all", 3) == 0)
            bit = all_layers;
        for (size_t k = 0; k < sizeof layer_names / sizeof layer_names[0] && !bit; k++)
            if (strlen(layer_names[k].name) == n && strncmp(s, layer_names[k].name, n) == 0)
                bit = layer_names[k].bit;
        if (!bit) {
            snprintf(bad, bad_size, "%.*s", (int)n, s);
            return false;
        }
        *layers |= bit;
        s += n + (s[n] == ',');
    }
    if (*layers)
        return true;
    snprintf(bad, bad_size, "(empty)");
    return false;
}

bool parse_png_mode(const char *s, int *indexed)
{
    *indexed = strcmp(s, "indexed") == 0;
    return *indexed || strcmp(s, "rgb") == 0;
}

/* "I0,I1,..." (signed integers) */
static bool parse_counts_signed(const char *s, int64_t *v, int *n)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    *n = 0;
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save))
        if (*n == CM_MAX_DIM || !parse_int64(tok, &v[(*n)++]))
            return false;
    return *n > 0;
}

/* One line of a --labels file: "ID TEXT" or "I0,I1,... TEXT". */
static bool parse_label(const char *line, cm_group_label *l)
{
    const size_t key = strcspn(line, " \t");
    const char *text = line + key + strspn(line + key, " \t");
    char head[256];
    if (key == 0 || key >= sizeof head || !*text || strlen(text) >= sizeof l->text)
        return false;
    memcpy(head, line, key);
    head[key] = 0;
    memset(l, 0, sizeof *l);
    snprintf(l->text, sizeof l->text, "%s", text);
    int64_t v[CM_MAX_DIM];
    int n = 0;
    if (!parse_counts_signed(head, v, &n))
        return false;
    l->by_anchor = strchr(head, ',') != NULL;
    if (!l->by_anchor)
        return v[0] >= 1 && v[0] <= UINT32_MAX && (l->id = (uint32_t)v[0], true);
    memcpy(l->anchor, v, sizeof v);
    return true;
}

bool png_opts_palette(const char *value, png_opts *po, char *msg, size_t msg_size)
{
    if (cm_palette_named(value, &po->palette, msg, msg_size) == CM_OK)
        return true;
    const bool a_file = strchr(value, '/') || strchr(value, '.');
    if (cm_palette_read(value, &po->file_palette, a_file ? msg : (char[64]){0},
                        a_file ? msg_size : 64) != CM_OK)
        return false; /* a name: the message lists the names */
    po->palette = &po->file_palette;
    po->palette_file = value;
    return true;
}

bool png_opts_labels(const char *path, png_opts *po, char *msg, size_t msg_size)
{
    FILE *f;
    if (cm_input_open(path, "the labels file", 1 << 20, &f, msg, msg_size) != CM_OK)
        return false;
    po->labels_file = path;
    char line[512];
    bool ok = true;
    for (int no = 1; ok && fgets(line, sizeof line, f); no++) {
        line[strcspn(line, "\r\n")] = 0;
        const char *s = line + strspn(line, " \t");
        if (!*s || *s == '#')
            continue;
        if (po->n_labels == PNG_LABELS_MAX) {
            snprintf(msg, msg_size, "%s: more than %d labels", path, PNG_LABELS_MAX);
            ok = false;
        } else if (!parse_label(s, &po->labels[po->n_labels++])) {
            snprintf(msg, msg_size, "%s:%d: '%.60s' is not 'ID TEXT' or 'I0,I1 TEXT' (text up to "
                     "63 characters)", path, no, s);
            ok = false;
        }
    }
    fclose(f);
    return ok;
}



bool png_opts_draws(const png_opts *po) { return po->path || po->svg || po->pdf; }

bool png_opts_apart(const png_opts *po, const char *db, bool db_written, char *msg,
                    size_t msg_size)
{
    const cm_file_use files[] = {
        {db, "the database", db_written, true},     {po->path, "the PNG", true, false},
        {po->svg, "the SVG", true, false},             {po->pdf, "the PDF", true, false},
        {po->palette_file, "the palette", false, false},
        {po->labels_file, "the labels file", false, false},
    };
    return cm_files_apart(files, sizeof files / sizeof *files, msg, msg_size) == CM_OK;
}

void view_cells(const cm_lattice *lat, const double lo[2], const double hi[2], const cm_box *within,
                cm_box *out)
{
    *out = *within;
    cm_rect_box(lat, lat->dim < 2 ? lat->dim : 2, lo, hi, out);
    for (int d = 2; d < lat->dim; d++) {
        out->lo[d] = within->lo[d] + (within->hi[d] - within->lo[d]) / 2;
        out->hi[d] = out->lo[d] + 1;
    }
}

void default_image_size(const cm_lattice *lat, const cm_box *box, int *width, int *height)
{
    const uint64_t nx = (uint64_t)(box->hi[0] - box->lo[0]);
    const uint64_t ny = lat->dim > 1 ? (uint64_t)(box->hi[1] - box->lo[1]) : 64;
    const uint64_t most = nx > ny ? nx : ny;
    const double shrink = most > MAX_DEFAULT_SIDE ? (double)MAX_DEFAULT_SIDE / (double)most : 1.0;
    *width = (int)((double)nx * shrink + 0.5);
    *height = (int)((double)ny * shrink + 0.5);
    *width = *width < 1 ? 1 : *width;
    *height = *height < 1 ? 1 : *height;
}

/* A figure with text gets FIGURE_SIDE pixels on its longer side (keeping
 * the cells' aspect) when the cells would make it smaller. */
static void figure_size(const cm_lattice *lat, const cm_box *box, unsigned layers, int *w, int *h)
{
    default_image_size(lat, box, w, h);
    if (lat->dim == 1 && (layers & (CM_LAYER_OVERLAYS | CM_LAYERS_TEXT)))
        *h = *w; /* room for the map's graph */
    const int most = *w > *h ? *w : *h;
    if (!(layers & CM_LAYERS_TEXT) || most >= FIGURE_SIDE)
        return;
    *w = (int)lround((double)*w * FIGURE_SIDE / most);
    *h = (int)lround((double)*h * FIGURE_SIDE / most);
    *w = *w < 200 ? 200 : *w;
    *h = *h < 200 ? 200 : *h;
}

const char *figure_font(void)
{
    const char *env = getenv("CELLMAP_FONT");
    return env && *env ? env : CELLMAP_FONT_PATH;
}

static void layers_text(unsigned layers, char *out, size_t size)
{
    size_t used = 0;
    out[0] = 0;
    for (size_t k = 0; k < sizeof layer_names / sizeof layer_names[0] && used < size; k++)
        if (layers & layer_names[k].bit)
            used += (size_t)snprintf(out + used, size - used, "%s%s", used ? "," : "",
                                     layer_names[k].name);
}

/* The provenance texts every basin PNG carries; `view` says what was drawn. */
typedef struct provenance {
    char params[2048], lattice[512], view[CM_MAX_DIM * 64 + 256], layers[128];
    cm_png_text texts[8];
    int n;
} provenance;

static void make_provenance(const basin_png *b, const char *view, unsigned layers, provenance *p)
{
    const cm_lattice *lat = b->lat;
    const cm_box *box = &b->cells->box;
    char state[CM_MAX_DIM * 64], origin[CM_MAX_DIM * 32], width[CM_MAX_DIM * 32],
        counts[CM_MAX_DIM * 24];
    size_t used[3] = {0, 0, 0};
    for (int d = 0; d < lat->dim; d++) { /* every dimension, not only the drawn two */
        const char *sep = d ? "," : "";
        used[0] += (size_t)snprintf(origin + used[0], sizeof origin - used[0], "%s%s", sep,
                                    CM_NUM(lat->origin[d]));
        used[1] += (size_t)snprintf(width + used[1], sizeof width - used[1], "%s%s", sep,
                                    CM_NUM(lat->width[d]));
        used[2] += (size_t)snprintf(counts + used[2], sizeof counts - used[2], "%s%lld",
                                    d ? "x" : "", (long long)(box->hi[d] - box->lo[d]));
    }
    cm_params_json(&b->model->values, p->params, sizeof p->params);
    snprintf(p->lattice, sizeof p->lattice, "origin %s width %s", origin, width);
    cm_box_text(lat, box, state, sizeof state);
    snprintf(p->view, sizeof p->view, "box %s cells %s%s", state, counts, view);
    layers_text(layers, p->layers, sizeof p->layers);
    const cm_png_text texts[] = {{"Software", "cellmap " CELLMAP_VERSION},
                                 {"Model", b->model->name},
                                 {"Parameters", p->params},
                                 {"Lattice", p->lattice},
                                 {"View", p->view},
                                 {"Layers", p->layers}};
    p->n = 6;
    memcpy(p->texts, texts, sizeof texts);
}

/* --min-basin, or its default: single-cell groups fold where a legend
 * would otherwise list hundreds of them; machine images fold nothing. */
static uint64_t min_basin_of(const png_opts *po, unsigned layers)
{
    return po->min_basin ? po->min_basin : (layers & CM_LAYER_LEGEND) ? 2 : 1;
}

/* --layers, or the command's default. */
static unsigned layers_of(const png_opts *po)
{
    return po->layers           ? po->layers
           : po->default_layers ? po->default_layers
                                : CM_LAYER_BASIN | CM_LAYER_ATTRACTORS;
}

bool figure_needs_gl(const png_opts *po, const cm_model *m)
{
    return po->path && !po->indexed && cm_plot_needs_gl(layers_of(po), m, m->dim);
}

bool figure_draws_steps(const png_opts *po) { return (layers_of(po) & CM_LAYER_STEPS) != 0; }

bool parse_aspect(const char *s, double *aspect)
{
    char *end = NULL;
    if (strcmp(s, "equal") == 0)
        *aspect = 1;
    else if (strcmp(s, "auto") == 0)
        *aspect = ASPECT_AUTO;
    else if ((*aspect = strtod(s, &end)) > 0 && *end == '\0' && *aspect <= 1e6 &&
             *aspect >= 1e-6)
        return true;
    else
        return false;
    return true;
}

double png_opts_font_pixels(const png_opts *po)
{
    return po->font_size > 0 ? po->font_size * (po->dpi > 0 ? po->dpi : 96) / 72 : 0;
}

/* The renderer's aspect for the figure of model m (render/figure.h). */
static double aspect_of(const png_opts *po, const cm_model *m)
{
    if (po->aspect > 0)
        return po->aspect;
    return po->aspect == 0 && m && m->equal_axes ? 1 : 0;
}

/* The renderer's options for the figure of b. */
static void figure_options(const basin_png *b, cm_render_options *out)
{
    const png_opts *po = b->opts;
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.layers = layers_of(po);
    ro.min_basin = min_basin_of(po, ro.layers);
    ro.legend_groups = po->legend_groups;
    ro.palette = po->palette;
    ro.labels = po->labels;
    ro.n_labels = po->n_labels;
    ro.sink_label = po->sink_label;
    ro.group_noun = po->group_noun;
    ro.title = po->title;
    ro.aspect = aspect_of(po, b->model);
    ro.font_px = png_opts_font_pixels(po);
    ro.dpi = po->dpi;
    ro.width = po->width;
    ro.height = po->height;
    if (!ro.width || !ro.height)
        figure_size(b->lat, &b->cells->box, ro.layers, &ro.width, &ro.height);
    memcpy(ro.lo, b->lo, sizeof ro.lo);
    memcpy(ro.hi, b->hi, sizeof ro.hi);
    ro.model = b->model;
    ro.font_path = figure_font();
    ro.gl = b->gl;
    *out = ro;
}

static cm_status write_figure(const basin_png *b, char *msg, size_t msg_size)
{
    const png_opts *po = b->opts;
    cm_render_options ro;
    figure_options(b, &ro);
    uint8_t *rgba = cm_cells_array((size_t)ro.width * (size_t)ro.height * 4);
    if (!rgba)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a %dx%d image", ro.width,
                       ro.height);
    cm_render_info info;
    cm_status st = cm_render_figure(b->lat, b->cells, b->groups, &ro, rgba, &info, msg, msg_size);
    if (st == CM_OK && info.overlays_truncated)
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "the view holds too many overlay lines to draw; zoom in or leave out the "
                     "overlays layer");
    if (st == CM_OK) {
        char view[256];
        provenance p;
        snprintf(view, sizeof view, " view %.9g:%.9g,%.9g:%.9g plot %d,%d %dx%d", info.lo[0],
                 info.hi[0], info.lo[1], info.hi[1], info.plot_x, info.plot_y, info.plot_w,
                 info.plot_h);
        make_provenance(b, view, ro.layers, &p);
        st = cm_png_write(po->path, rgba, ro.width, ro.height, po->dpi, p.texts, p.n, msg, msg_size);
    }
    free(rgba);
    return st;
}

/* "id:class ..." for the groups with cells in the image. */
static char *group_classes(const cm_raster *ras, uint32_t ngroups)
{
    size_t size = 64 + 24 * (size_t)ngroups, used = 0;
    char *out = malloc(size);
    if (!out)
        return NULL;
    out[0] = 0;
    for (uint32_t g = 1; g <= ngroups; g++)
        if (ras->group_cells[g])
            used += (size_t)snprintf(out + used, size - used, "%s%u:%u", used ? " " : "", g,
                                     ras->classes[g]);
    return out;
}

/* One pixel per cell of the slice, its colour class; row 0 at the top. */
static cm_status write_indexed(const basin_png *b, char *msg, size_t msg_size)
{
    cm_slice s;
    cm_raster ras;
    cm_slice_of(b->lat, b->cells, NULL, 0, &s);
    if (s.nx > CM_RENDER_MAX_SIDE || s.ny > CM_RENDER_MAX_SIDE)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "an indexed image has one pixel per cell: %llux%llu cells exceed %d a "
                       "side; choose a smaller view",
                       (unsigned long long)s.nx, (unsigned long long)s.ny, CM_RENDER_MAX_SIDE);
    cm_status st =
        cm_raster_build(b->lat, b->cells, b->groups, &s, CM_RASTER_CLASSES,
                        min_basin_of(b->opts, 0), b->opts->palette, &ras, msg, msg_size);
    if (st != CM_OK)
        return st;
    st = cm_raster_paint(b->lat, b->cells, b->groups, 1, 1, &ras, msg, msg_size);
    const int n = cm_class_count(b->opts->palette);
    uint8_t palette[3 * 256];
    for (int k = 0; k < n; k++) {
        const cm_rgb c = cm_class_colour(b->opts->palette, k);
        palette[3 * k] = c.r;
        palette[3 * k + 1] = c.g;
        palette[3 * k + 2] = c.b;
    }
    uint8_t *rows = malloc(s.nx * s.ny);
    char *groups = group_classes(&ras, b->cells->ngroups);
    if (!rows || !groups)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for an indexed image");
    if (st == CM_OK) {
        for (uint64_t j = 0; j < s.ny; j++) /* the raster's row 0 is the lowest */
            memcpy(rows + (s.ny - 1 - j) * s.nx, ras.pixels + j * s.nx, s.nx);
        provenance p;
        make_provenance(b, " mode indexed", 0, &p);
        /* by attractors (the sink's label set) the sink is what diverges,
         * and the grey of sticking zones also marks the cells outside */
        p.texts[p.n++] = (cm_png_text){
            "Classes", b->opts->sink_label
                           ? "0 not computed, 1 diverged, 2 footprint cell of an attractor, 3 "
                             "sticking-zone basin or outside/undecided, 4 rest cell, 5 other "
                             "(--min-basin), 6.. attractor colours"
                           : "0 not computed, 1 sink, 2 periodic cell of an attractor, 3 "
                             "sticking-zone basin, 4 rest cell, 5 other (--min-basin), 6.. group "
                             "colours"};
        p.texts[p.n++] = (cm_png_text){"Group classes", groups};
        st = cm_png_write_indexed(b->opts->path, rows, (int)s.nx, (int)s.ny, b->opts->dpi, palette, n, p.texts,
                                  p.n, msg, msg_size);
    }
    free(rows);
    free(groups);
    cm_raster_free(&ras);
    return st;
}

cm_status figure_check_layout(const png_opts *po, const cm_model *m, const cm_lattice *lat,
                              const cm_box *box, char *msg, size_t msg_size)
{
    if (po->indexed)
        return CM_OK;
    cm_render_options ro;
    memset(&ro, 0, sizeof ro);
    ro.layers = layers_of(po);
    ro.width = po->width;
    ro.height = po->height;
    cm_box shown = *box;
    if (po->has_view)
        view_cells(lat, po->lo, po->hi, box, &shown);
    if (!ro.width || !ro.height)
        figure_size(lat, &shown, ro.layers, &ro.width, &ro.height);
    for (int d = 0; d < 2 && d < lat->dim; d++) {
        ro.lo[d] = po->has_view ? po->lo[d] : cm_lattice_edge(lat, d, box->lo[d]);
        ro.hi[d] = po->has_view ? po->hi[d] : cm_lattice_edge(lat, d, box->hi[d]);
    }
    ro.model = m;
    ro.title = po->title;
    ro.aspect = aspect_of(po, m);
    ro.font_path = figure_font();
    return cm_render_check(&ro, lat->dim, msg, msg_size);
}

cm_status figure_check(const png_opts *po, const cm_model *m, const cm_lattice *lat,
                       const cm_box *box, char *msg, size_t msg_size)
{
    cm_status st = outfile_check_path(po->path, false, msg, msg_size);
    if (st == CM_OK)
        st = outfile_check_path(po->svg, false, msg, msg_size);
    if (st == CM_OK)
        st = outfile_check_path(po->pdf, false, msg, msg_size);
    if (st == CM_OK && po->pdf) /* a missing librsvg stops the command before its work */
        st = cm_pdf_load(msg, msg_size);
    return st == CM_OK ? figure_check_layout(po, m, lat, box, msg, msg_size) : st;
}

/* The figure as SVG (render/svg.h), for outfile_vector. */
static cm_status figure_svg(FILE *f, const void *user, int cell_pixels, char *msg,
                            size_t msg_size)
{
    const basin_png *b = user;
    cm_render_options ro;
    figure_options(b, &ro);
    ro.svg_cell_pixels = cell_pixels;
    return cm_render_svg(b->lat, b->cells, b->groups, &ro, f, msg, msg_size);
}

/* b's figure drawn by attractors: its cells relabelled in a copy of their
 * groups and steps (attractor_view does not change images). */
static cm_status write_by_attractors(const basin_png *b, char *msg, size_t msg_size)
{
    cm_region view = *b->cells;
    const uint64_t n = view.ncells;
    const bool copy = b->spare != b->cells;
    view.group = copy ? cm_cells_array((n + 1) * sizeof *view.group) : b->spare->group;
    view.step = copy ? cm_cells_array((n + 1) * sizeof *view.step) : b->spare->step;
    cm_group_info *groups = NULL;
    uint32_t count = 0;
    png_opts *po = malloc(sizeof *po);
    int32_t *own = b->labels ? NULL : cm_cells_array((n + 1) * sizeof *own);
    const int32_t *label = b->labels ? b->labels : own;
    cm_status st = view.group && view.step && po && label
                       ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the figure");
    if (st == CM_OK && !b->labels)
        st = cm_attractor_cell_labels(b->attractors, b->cells, b->computed, own, msg, msg_size);
    if (st == CM_OK && copy) {
        memcpy(view.group, b->cells->group, n * sizeof *view.group);
        memcpy(view.step, b->cells->step, n * sizeof *view.step);
    }
    if (st == CM_OK)
        st = attractor_view(b->attractors, &view, label, &groups, &count, msg, msg_size);
    free(own);
    if (st == CM_OK) {
        *po = *b->opts;
        po->n_labels = attractor_legend(b->attractors, count, po->labels, po->n_labels,
                                        PNG_LABELS_MAX);
        po->sink_label = "diverged";
        po->group_noun = "attractor";
        basin_png by = *b;
        by.opts = po;
        by.cells = &view;
        by.groups = groups;
        by.attractors = NULL;
        by.labels = NULL;
        by.spare = NULL;
        st = figure_write(&by, msg, msg_size);
    }
    if (copy) {
        free(view.group);
        free(view.step);
    }
    free(groups);
    free(po);
    return st;
}

cm_status figure_write(const basin_png *b, char *msg, size_t msg_size)
{
    if (b->attractors)
        return write_by_attractors(b, msg, msg_size);
    cm_status st = CM_OK;
    if (b->opts->path)
        st = b->opts->indexed ? write_indexed(b, msg, msg_size) : write_figure(b, msg, msg_size);
    if (st == CM_OK && b->opts->svg)
        st = outfile_vector(b->opts->svg, false, figure_svg, b, msg, msg_size);
    if (st == CM_OK && b->opts->pdf)
        st = outfile_vector(b->opts->pdf, true, figure_svg, b, msg, msg_size);
    return st;
}

cm_status figure_file_view(cm_store *s, const cm_cluster *cl, const png_opts *po,
                           const char *slice_text, double lo[2], double hi[2], cm_box *box,
                           char *msg, size_t msg_size)
{
    const cm_lattice *lat = &cl->lat;
    cm_box bounds;
    cm_cluster_bounds(cl, &bounds);
    const int dims = lat->dim < 2 ? lat->dim : 2;
    if (po->has_view) {
        memcpy(lo, po->lo, 2 * sizeof *lo);
        memcpy(hi, po->hi, 2 * sizeof *hi);
    } else if (project_view_note(s, dims, lo, hi, (char[256]){0}, 256) != CM_OK) {
        cm_box_rect(lat, &bounds, dims, lo, hi);
    }
    if (lat->dim == 1)
        lo[1] = hi[1] = 0;
    view_cells(lat, lo, hi, &bounds, box);
    if (!slice_text)
        return CM_OK;
    double v[CM_MAX_DIM];
    int n = 0;
    if (!parse_doubles(slice_text, v, &n, CM_MAX_DIM) || n != lat->dim - 2)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the slice '%s' must be %d coordinate(s) of dimensions 3..", slice_text,
                       lat->dim > 2 ? lat->dim - 2 : 0);
    for (int d = 2; d < lat->dim; d++) {
        box->lo[d] = (int64_t)floor((v[d - 2] - lat->origin[d]) / lat->width[d]);
        box->hi[d] = box->lo[d] + 1;
    }
    return CM_OK;
}

/* A cm_progress_fn of the view's reading, told to the hooks. */
typedef struct reading {
    const work_hooks *hooks;
    uint64_t cells;
} reading;

static int read_progress(void *user, const char *phase, double fraction)
{
    const reading *r = user;
    (void)phase;
    work_progress(r->hooks, (uint64_t)(fraction * (double)r->cells), "reading the view");
    return work_stop(r->hooks) != NULL;
}

cm_status figure_of_file(cm_store *s, const cm_store_info *info, cm_cluster *cl,
                         const char *source, const png_opts *po, const cm_box *box,
                         const double lo[2], const double hi[2], const cm_attractor_options *o,
                         const work_hooks *hooks, char *msg, size_t msg_size)
{
    cm_model m;
    cm_model_set set = {0};
    char why[1024];
    if (model_of_store(info, &set, &m, why, sizeof why) != CM_OK)
        return cm_fail(CM_EFORMAT, msg, msg_size, "%s: %s", source, why);
    cm_region flat;
    memset(&flat, 0, sizeof flat);
    uint64_t sink = 0;
    cm_group_info *groups = calloc((size_t)cl->ngroups + 1, sizeof *groups);
    cm_status st = groups ? cm_store_groups(s, groups, cl->ngroups, &sink, msg, msg_size)
                          : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for groups");
    cm_attractor_set att;
    memset(&att, 0, sizeof att);
    cluster_ends ends;
    memset(&ends, 0, sizeof ends);
    if (st == CM_OK && po->by == BY_ATTRACTORS) /* lists the exits only to find fates */
        st = file_attractors(s, info, &m, cl, &ends, groups, o, &att, msg, msg_size);
    if (st == CM_OK && po->by == BY_ATTRACTORS)
        cluster_ends_lookup(&ends, cl);
    reading r = {hooks, cm_box_cells(box)};
    if (st == CM_OK)
        st = cm_cluster_flatten_progress(cl, box, &flat, read_progress, &r, msg, msg_size);
    const basin_png png = {po,     &m,   &cl->lat, &flat, groups, {lo[0], lo[1]}, {hi[0], hi[1]},
                           NULL, po->by == BY_ATTRACTORS ? &att : NULL, &ends.computed, NULL, &flat};
    if (st == CM_OK)
        st = figure_write(&png, msg, msg_size);
    cm_region_free(&flat);
    cluster_ends_close(&ends);
    cm_attractors_free(&att);
    free(groups);
    cm_model_release(&m);
    return st;
}
