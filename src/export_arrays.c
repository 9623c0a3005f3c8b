/* src/export_arrays.c - n-D .npy arrays of a window's groups and steps
 * (src/export_arrays.h). */
#include "src/export_arrays.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/palette.h"
#include "src/interrupt.h"
#include "lib/attractor_report.h"
#include "lib/json.h"
#include "src/outfile.h"

enum { SLAB_CELLS = 1 << 22 }; /* cells flattened at a time */

void array_sidecar_path(const char *npy, char *out, size_t size)
{
    const size_t n = strlen(npy);
    const bool has_suffix = n > 4 && strcmp(npy + n - 4, ".npy") == 0;
    snprintf(out, size, "%.*s.json", (int)(has_suffix ? n - 4 : n), npy);
}

/* The .npy header (format 1.0): a dict padded with spaces to a multiple
 * of 64 bytes, then a newline. */
static bool npy_header(FILE *f, const cm_box *w)
{
    char header[512];
    int n = snprintf(header, sizeof header, "{'descr': '<i4', 'fortran_order': False, 'shape': (");
    for (int d = 0; d < w->dim; d++)
        n += snprintf(header + n, sizeof header - (size_t)n, "%lld,%s",
                      (long long)(w->hi[d] - w->lo[d]), d + 1 < w->dim ? " " : "");
    n += snprintf(header + n, sizeof header - (size_t)n, "), }");
    while ((10 + n + 1) % 64)
        header[n++] = ' ';
    header[n++] = '\n';
    const unsigned char magic[10] = {
        0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, (unsigned char)(n & 0xff), (unsigned char)(n >> 8)};
    return fwrite(magic, 1, 10, f) == 10 && fwrite(header, 1, (size_t)n, f) == (size_t)n;
}

static void put_i32(unsigned char *p, int32_t v)
{
    const uint32_t u = (uint32_t)v;
    for (int b = 0; b < 4; b++)
        p[b] = (unsigned char)(u >> (8 * b));
}

/* The slab's cells in C order (dimension 0 slowest): one int32 each, the
 * label of each cell (label[index] by attractors, else its group; -1 not
 * computed); in_window counts the cells of each group, by_label those of
 * each label (at label + 2: -2 and -1 first). */
static bool write_slab(const cm_region *flat, const int32_t *label, FILE *labels, FILE *steps,
                       uint64_t *in_window, uint64_t *by_label)
{
    const cm_box *b = &flat->box;
    const int dim = b->dim;
    int64_t n[CM_MAX_DIM], i[CM_MAX_DIM] = {0};
    for (int d = 0; d < dim; d++)
        n[d] = b->hi[d] - b->lo[d];
    const uint64_t cells = cm_box_cells(b);
    bool ok = true;
    for (uint64_t k = 0; k < cells && ok; k++) {
        uint64_t index = 0, stride = 1; /* the flat region has dimension 0 fastest */
        for (int d = 0; d < dim; d++) {
            index += (uint64_t)i[d] * stride;
            stride *= (uint64_t)n[d];
        }
        const uint32_t g = flat->group[index];
        unsigned char v[4];
        const int32_t l = label                ? label[index]
                          : g == CM_GROUP_NONE ? -1
                                               : (int32_t)g;
        if (g != CM_GROUP_NONE)
            in_window[g]++;
        by_label[l + 2]++;
        put_i32(v, l);
        ok = !labels || fwrite(v, 1, 4, labels) == 4;
        put_i32(v, g == CM_GROUP_NONE ? -1 : (int32_t)flat->step[index]);
        ok = ok && (!steps || fwrite(v, 1, 4, steps) == 4);
        for (int d = dim - 1; d >= 0; d--) { /* the next index in C order */
            if (++i[d] < n[d])
                break;
            i[d] = 0;
        }
    }
    return ok;
}

static void write_sidecar_groups(json *j, const array_export *x, const cm_lattice *lat,
                                 const uint64_t *in_window)
{
    uint8_t *classes = calloc((size_t)x->ngroups + 1, 1);
    if (classes)
        cm_palette_classes(NULL, x->groups, x->ngroups, lat, in_window + 1, 1, classes);
    json_array(j, "groups");
    for (uint32_t k = 0; k < x->ngroups; k++) {
        if (!in_window[k + 1])
            continue;
        const cm_group_info *g = &x->groups[k];
        json_object(j, NULL);
        json_group_fields(j, g, lat);
        json_uint(j, "in_view", in_window[k + 1]);
        if (classes) {
            const cm_rgb c = cm_class_colour(NULL, classes[k]);
            char hex[8];
            snprintf(hex, sizeof hex, "#%02x%02x%02x", c.r, c.g, c.b);
            json_str(j, "colour", hex);
        }
        json_object_end(j);
    }
    json_array_end(j);
    free(classes);
}

/* The attractors with cells in the window, as solve --json lists them,
 * with their cells in it. */
static void write_sidecar_attractors(json *j, const array_export *x, const cm_lattice *lat,
                                     const uint64_t *in_window)
{
    const cm_attractor_set *s = x->attractors;
    json_array(j, "attractors");
    for (uint32_t k = 0; k < s->n; k++) {
        if (!in_window[s->a[k].id + 2])
            continue;
        const cm_attractor *a = &s->a[k];
        json_object(j, NULL);
        json_attractor_fields(j, a, lat);
        json_uint(j, "in_view", in_window[a->id + 2]);
        json_object_end(j);
    }
    json_array_end(j);
}

static bool write_sidecar(const char *npy, const char *kind, const array_export *x,
                          const cm_lattice *lat, const cm_box *w, const uint64_t *in_window,
                          const uint64_t *by_label)
{
    const bool by_attractors = x->attractors && strcmp(kind, "labels") == 0;
    char path[CM_OUTPUT_PATH_MAX];
    array_sidecar_path(npy, path, sizeof path);
    outfile o;
    if (!outfile_open("export", path, &o))
        return false;
    json j;
    json_begin(&j, o.f, "export");
    json_str(&j, "array", kind);
    json_str(&j, "file", npy);
    json_str(&j, "source", x->source);
    json_str(&j, "dtype", "<i4");
    json_str(&j, "order", "C");
    json_array(&j, "shape");
    for (int d = 0; d < w->dim; d++)
        json_int(&j, NULL, w->hi[d] - w->lo[d]);
    json_array_end(&j);
    json_array(&j, "axes"); /* axis k of the array is state dimension k */
    for (int d = 0; d < w->dim; d++)
        json_str(&j, NULL, x->names[d]);
    json_array_end(&j);
    json_array(&j, "first_cell");
    for (int d = 0; d < w->dim; d++)
        json_int(&j, NULL, w->lo[d]);
    json_array_end(&j);
    json_box(&j, "box", lat, w);
    json_lattice(&j, lat);
    json_str(&j, "model", x->info->model);
    json_raw(&j, "params", x->info->params);
    json_str(&j, "by", by_attractors ? "attractors" : "groups");
    json_object(&j, "values");
    json_str(&j, "-1", "not computed");
    if (by_attractors) {
        json_str(&j, "-2", "outside: the sequence left the computed cells, or its group's true "
                           "orbit was undecided");
        json_str(&j, "0", "diverged: its group's true orbit diverges");
        json_str(&j, "k", "attractor k");
    } else if (strcmp(kind, "labels") == 0) {
        json_str(&j, "0", "the sink (the sequence leaves the cluster)");
        json_str(&j, "k", "group k");
    } else {
        json_str(&j, "k", "steps to the group's periodic cells");
    }
    json_object_end(&j);
    if (by_attractors)
        write_sidecar_attractors(&j, x, lat, by_label);
    else
        write_sidecar_groups(&j, x, lat, in_window);
    json_end(&j);
    return outfile_close("export", &o, true);
}

bool export_arrays(cm_cluster *c, const cm_box *window, const array_export *x, progress *pr)
{
    outfile labels, steps;
    const bool has_labels = x->labels != NULL, has_steps = x->steps != NULL;
    const uint32_t labels_n = x->attractors ? x->attractors->n : x->ngroups;
    uint64_t *in_window = calloc((size_t)x->ngroups + 2, sizeof *in_window);
    uint64_t *by_label = calloc((size_t)labels_n + 3, sizeof *by_label);
    if (!in_window || !by_label) {
        free(by_label);
        fprintf(stderr, "cellmap export: out of memory for %u groups\n", x->ngroups);
        return false;
    }
    bool ok = (!has_labels || outfile_open("export", x->labels, &labels));
    if (ok && has_steps && !outfile_open("export", x->steps, &steps)) {
        if (has_labels)
            outfile_close("export", &labels, false);
        ok = false;
    }
    if (!ok) {
        free(in_window);
        return false;
    }
    ok = (!has_labels || npy_header(labels.f, window)) && (!has_steps || npy_header(steps.f, window));
    /* slabs along dimension 0, the slowest in C order */
    const uint64_t per_layer = cm_box_cells(window) / (uint64_t)(window->hi[0] - window->lo[0]);
    const int64_t layers = per_layer >= SLAB_CELLS ? 1 : (int64_t)(SLAB_CELLS / per_layer);
    uint64_t done = 0;
    char msg[1024] = "";
    for (int64_t at = window->lo[0]; at < window->hi[0] && ok; at += layers) {
        cm_box slab = *window;
        slab.lo[0] = at;
        slab.hi[0] = at + layers < window->hi[0] ? at + layers : window->hi[0];
        cm_region flat;
        if (cm_cluster_flatten(c, &slab, &flat, msg, sizeof msg) != CM_OK) {
            ok = false;
            break;
        }
        int32_t *label = x->attractors ? malloc((flat.ncells + 1) * sizeof *label) : NULL;
        if (x->attractors && (!label || cm_attractor_cell_labels(x->attractors, &flat, x->computed,
                                                                  label, msg, sizeof msg) != CM_OK)) {
            if (!label)
                snprintf(msg, sizeof msg, "out of memory for the labels");
            ok = false;
        } else {
            errno = 0;
            ok = write_slab(&flat, label, has_labels ? labels.f : NULL,
                            has_steps ? steps.f : NULL, in_window, by_label);
            if (!ok) /* the file a write failed on, and why */
                cm_output_fail(has_labels && ferror(labels.f) ? x->labels : x->steps,
                               errno ? errno : EIO, msg, sizeof msg);
        }
        free(label);
        done += flat.ncells;
        cm_region_free(&flat);
        if (ok && interrupt_requested()) {
            snprintf(msg, sizeof msg, "interrupted (Ctrl-C): --labels and --steps were not written");
            ok = false;
        }
        progress_say(pr, done, NULL);
    }
    progress_end(pr);
    if (!ok && msg[0])
        fprintf(stderr, "cellmap export: %s\n", msg);
    if (has_labels)
        ok = outfile_close("export", &labels, ok) && ok;
    if (has_steps)
        ok = outfile_close("export", &steps, ok) && ok;
    if (ok && has_labels)
        ok = write_sidecar(x->labels, "labels", x, &c->lat, window, in_window, by_label);
    if (ok && has_steps)
        ok = write_sidecar(x->steps, "steps", x, &c->lat, window, in_window, by_label);
    free(in_window);
    free(by_label);
    return ok;
}
