/* lib/json.c - the --json writer (lib/json.h). */
#include "lib/json.h"

#include <math.h>

#include "cellmap/numtext.h"
#include "cellmap/store.h"

static void item(json *j, const char *key)
{
    if (j->has_items[j->depth])
        fputc(',', j->f);
    j->has_items[j->depth] = true;
    if (key) {
        json_str_text(j->f, key);
        fputc(':', j->f);
    }
}

void json_str_text(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\')
            fprintf(f, "\\%c", *p);
        else if (*p < 0x20)
            fprintf(f, "\\u%04x", *p);
        else
            fputc(*p, f);
    }
    fputc('"', f);
}

static void open_nested(json *j, const char *key, char bracket)
{
    item(j, key);
    fputc(bracket, j->f);
    if (j->depth + 1 < JSON_MAX_DEPTH)
        j->depth++;
    j->has_items[j->depth] = false;
}

static void close_nested(json *j, char bracket)
{
    fputc(bracket, j->f);
    if (j->depth > 0)
        j->depth--;
}

void json_begin(json *j, FILE *f, const char *command)
{
    j->f = f;
    j->depth = 0;
    j->has_items[0] = false;
    fputc('{', f);
    json_str(j, "command", command);
}

void json_end(json *j)
{
    fputs("}\n", j->f);
}

void json_object(json *j, const char *key) { open_nested(j, key, '{'); }
void json_object_end(json *j) { close_nested(j, '}'); }
void json_array(json *j, const char *key) { open_nested(j, key, '['); }
void json_array_end(json *j) { close_nested(j, ']'); }

void json_num(json *j, const char *key, double v)
{
    item(j, key);
    if (isfinite(v))
        fputs(CM_NUM(v), j->f);
    else
        fputs("null", j->f);
}

void json_num_near(json *j, const char *key, double v, double tol)
{
    item(j, key);
    if (isfinite(v))
        fputs(cm_num_text_near(v, tol, (char[CM_NUM_TEXT]){0}), j->f);
    else
        fputs("null", j->f);
}

void json_seconds(json *j, const char *key, double s)
{
    json_num_near(j, key, s, 5e-7);
}

void json_nums(json *j, const char *key, const double *v, int n)
{
    json_array(j, key);
    for (int i = 0; i < n; i++)
        json_num(j, NULL, v[i]);
    json_array_end(j);
}

void json_uint(json *j, const char *key, uint64_t v)
{
    item(j, key);
    fprintf(j->f, "%llu", (unsigned long long)v);
}

void json_int(json *j, const char *key, int64_t v)
{
    item(j, key);
    fprintf(j->f, "%lld", (long long)v);
}

void json_str(json *j, const char *key, const char *s)
{
    item(j, key);
    json_str_text(j->f, s ? s : "");
}

void json_bool(json *j, const char *key, bool v)
{
    item(j, key);
    fputs(v ? "true" : "false", j->f);
}

void json_raw(json *j, const char *key, const char *text)
{
    item(j, key);
    fputs(text, j->f);
}

void json_model(json *j, const cm_model *m)
{
    char params[8192];
    cm_params_json(&m->values, params, sizeof params);
    json_str(j, "model", m->name);
    json_raw(j, "params", params);
    json_array(j, "state");
    for (int d = 0; d < m->dim; d++)
        json_str(j, NULL, cm_model_coord_name(m, d));
    json_array_end(j);
}

void json_lattice(json *j, const cm_lattice *lat)
{
    json_object(j, "lattice");
    json_nums(j, "origin", lat->origin, lat->dim);
    json_nums(j, "width", lat->width, lat->dim);
    json_object_end(j);
}

void json_box(json *j, const char *key, const cm_lattice *lat, const cm_box *box)
{
    json_array(j, key);
    for (int d = 0; d < box->dim; d++) {
        const double tol = CM_CELL_TOLERANCE * lat->width[d];
        json_array(j, NULL);
        json_num_near(j, NULL, cm_lattice_edge(lat, d, box->lo[d]), tol);
        json_num_near(j, NULL, cm_lattice_edge(lat, d, box->hi[d]), tol);
        json_array_end(j);
    }
    json_array_end(j);
}

void json_group_fields(json *j, const cm_group_info *g, const cm_lattice *lat)
{
    json_uint(j, "id", g->id);
    json_str(j, "kind", cm_group_kind_name(g->kind));
    json_uint(j, "period", g->period);
    json_uint(j, "basin_cells", g->basin_cells);
    json_array(j, "centre");
    for (int d = 0; d < lat->dim; d++)
        json_num_near(j, NULL, g->centre[d], CM_CELL_TOLERANCE * lat->width[d]);
    json_array_end(j);
}

void json_groups(json *j, const cm_group_info *g, uint32_t n, const cm_lattice *lat)
{
    json_array(j, "groups");
    for (uint32_t k = 0; k < n; k++) {
        json_object(j, NULL);
        json_group_fields(j, &g[k], lat);
        json_object_end(j);
    }
    json_array_end(j);
}
