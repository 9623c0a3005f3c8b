/* lib/partition.c - the delayed map's Markov partition written (lib/partition.h). */
#include "lib/partition.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure.h"
#include "lib/json.h"

void partition_row_text(const cm_delay_partition *p, int i, char *out)
{
    for (int j = 0; j < p->r; j++)
        out[j] = (char)('0' + p->P[i][j]);
    out[p->r] = '\0';
}

static bool write_csv(const part_args *a, const cm_delay_partition *p, char *msg,
                         size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->out.csv, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f, "region,branch,lo,hi,row\n");
    char row[CM_DELAY_MAX_REGIONS + 1];
    for (int i = 0; i < p->r; i++) {
        partition_row_text(p, i, row);
        fprintf(o.f, "%d,%s,%.17g,%.17g,%s\n", i + 1, p->branch[i] ? "lower" : "upper", p->lo[i],
                p->hi[i], row);
    }
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

static bool write_png(const part_args *a, const cm_delay_partition *p, const char *params,
                         char *msg, size_t msg_size)
{
    double x[2][2 * CM_DELAY_MAX_REGIONS], y[2][2 * CM_DELAY_MAX_REGIONS];
    size_t n[2] = {0, 0};
    double top = 0, bottom = 0;
    for (int i = 0; i < p->r; i++) {
        const int c = i % 2, k = p->branch[i];
        for (int e = 0; e < 2; e++) {
            const double s = e ? p->hi[i] : p->lo[i];
            x[c][n[c]] = s;
            y[c][n[c]++] = p->a * s - p->b * k;
            top = fmax(top, p->a * s - p->b * k);
            bottom = fmin(bottom, p->a * s - p->b * k);
        }
    }
    const double one_x[2] = {1, 1}, one_y[2] = {bottom - 0.1, top + 0.1};
    const cm_rgb red = {215, 48, 39}, blue = {69, 117, 180}, grey = {150, 150, 150};
    const cm_series series[] = {
        {CM_SERIES_SEGMENTS, one_x, one_y, 2, grey, 1},
        {CM_SERIES_SEGMENTS, x[0], y[0], n[0], red, 4},
        {CM_SERIES_SEGMENTS, x[1], y[1], n[1], blue, 4},
    };
    char title[600];
    snprintf(title, sizeof title,
             "partition I_1..I_%d (alternating colours), x_(j-1) = 1 grey; %s",
             p->r, params);
    const cm_chart chart = {a->out.width,
                            a->out.height,
                            {p->x_l - 0.1, bottom - 0.1},
                            {p->x_r + 0.1, top + 0.1},
                            "x_(j-1)",
                            "x_j",
                            title,
                            NULL,
                            series,
                            3,
                            figure_font(),
                            0,
                            NULL,
                            0};
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}};
    return (outfile_charts(a->out.png, &chart, 1, texts, 2, msg, msg_size) == CM_OK);
}

part_args partition_defaults(void)
{
    return (part_args){.mo = {.name = "microchaos-delay"}, .out = {.width = 900, .height = 700}};
}

cm_status partition_compute(const part_args *a, part_result *r, char *msg, size_t msg_size)
{
    const cm_status st =
        param_sweep_base(&a->mo, "microchaos-delay", NULL, 0, &r->base, msg, msg_size);
    if (st != CM_OK)
        return st;
    char why[300];
    if (!cm_delay_partition_01(cm_params_get(&r->base, "a"), cm_params_get(&r->base, "b"), &r->p,
                               why, sizeof why))
        return cm_fail(CM_EINVAL, msg, msg_size, "%s; e.g. a=1.3,b=0.66 (Fig. 4.11)", why);
    return CM_OK;
}

cm_status partition_write(const part_args *a, const part_result *r, char *msg, size_t msg_size)
{
    char params[400];
    cm_params_format(&r->base, params, sizeof params);
    const bool ok = (!a->out.csv || write_csv(a, &r->p, msg, msg_size)) &&
                    (!a->out.png || write_png(a, &r->p, params, msg, msg_size));
    return ok ? CM_OK : CM_EIO;
}

/* The summary: the regions, their rows and whether the matrix is primitive. */
void partition_report(FILE *f, const cm_delay_partition *p)
{
    char row[CM_DELAY_MAX_REGIONS + 1];
    fprintf(f, "%d regions on the branches x_j = a x_(j-1) (upper) and a x_(j-1) - b "
               "(lower), x_(j-1) in (%.9g, %.9g):\n",
            p->r, p->x_l, p->x_r);
    for (int i = 0; i < p->r; i++) {
        partition_row_text(p, i, row);
        fprintf(f, "  I_%-2d %s (%.9g, %.9g)  %s\n", i + 1, p->branch[i] ? "lower" : "upper",
                p->lo[i], p->hi[i], row);
    }
    if (p->primitive_index)
        fprintf(f, "irreducible and primitive: every entry of P^%d is positive (r^2 - r = "
                   "%d)\n",
                p->primitive_index, p->r * p->r - p->r);
    else
        fprintf(f, "%s, not primitive\n", p->irreducible ? "irreducible" : "not irreducible");
}

void partition_json(const part_args *a, const part_result *r)
{
    const cm_delay_partition *p = &r->p;
    char row[CM_DELAY_MAX_REGIONS + 1];
    json j;
    json_begin(&j, stdout, "partition");
    param_base_json(&j, a->mo.name, &r->base);
    json_nums(&j, "ends", (const double[2]){p->x_l, p->x_r}, 2);
    json_array(&j, "regions");
    for (int i = 0; i < p->r; i++) {
        partition_row_text(p, i, row);
        json_object(&j, NULL);
        json_str(&j, "branch", p->branch[i] ? "lower" : "upper");
        json_nums(&j, "range", (const double[2]){p->lo[i], p->hi[i]}, 2);
        json_str(&j, "row", row);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_bool(&j, "irreducible", p->irreducible);
    json_int(&j, "primitive_index", p->primitive_index);
    json_end(&j);
}
