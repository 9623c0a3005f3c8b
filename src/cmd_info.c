/* cellmap info: what a .cmdb file holds, and what it costs on disk and in
 * memory. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/attractor_report.h"
#include "lib/json.h"
#include "lib/project.h"

static const char info_help[] =
    "usage: cellmap info FILE.cmdb [--json]\n\n"
    "Prints the model, parameters, lattice, the command that made the file, its\n"
    "regions and groups (largest basins first), and its size on disk and in memory.\n"
    "The file is opened read-only. info reads its records, not its cells (export\n"
    "and render read those, and report a damaged page), so it takes milliseconds\n"
    "on files of millions of cells.\n";

enum { SHOWN_GROUPS = 10 };

static void print_cells(const cm_lattice *lat, const int64_t *cell)
{
    double x[CM_MAX_DIM];
    char text[CM_MAX_DIM * CM_NUM_TEXT];
    cm_lattice_centre(lat, cell, x);
    cm_point_text(lat, x, ", ", text, sizeof text);
    fputs(text, stdout);
}

static void print_text(const char *path, const cm_store_info *info, const cm_box *bounds,
                       const cm_group_info *g, uint64_t sink, uint64_t largest_region,
                       const cm_attractor_set *att)
{
    const cm_lattice *lat = &info->lattice;
    printf("file %s: cellmap database format %d, written by cellmap %s\n", path, info->version,
           info->tool_version);
    printf("model %s %s\n", info->model, info->params);
    if (info->model_lib[0]) { /* a plugin's model: say whether it is still there and the same */
        cm_model_set set = {0};
        cm_model m;
        char msg[2048];
        if (model_of_store(info, &set, &m, msg, sizeof msg) == CM_OK) {
            printf("plugin %s (hash %s)\n", info->model_lib, info->model_lib_hash);
            cm_model_release(&m);
        } else {
            printf("plugin %s: %s\n", info->model_lib, msg);
        }
    }
    printf("lattice origin (");
    for (int d = 0; d < lat->dim; d++)
        printf("%s%s", d ? ", " : "", CM_NUM(lat->origin[d]));
    printf(") cell width (");
    for (int d = 0; d < lat->dim; d++)
        printf("%s%s", d ? ", " : "", CM_NUM(lat->width[d]));
    printf(")\nmade by: %s\n", info->command);
    char box[CM_MAX_DIM * 2 * CM_NUM_TEXT];
    cm_box_text(lat, bounds, box, sizeof box);
    printf("regions %u, cells %llu, bounding box %s (%llu cells)\n", info->regions,
           (unsigned long long)info->cells, box, (unsigned long long)cm_box_cells(bounds));
    if (att) {
        attractor_text(stdout, lat, att, info->cells, SHOWN_GROUPS);
    } else {
        printf("attractors: not in this file (written before format 7, or by a solve stopped "
               "before its end): solve --resume with the same options, or explore, adds them\n");
    }
    printf("cell groups %u periodic, sink basin %llu cells (%.1f%%)\n", info->groups,
           (unsigned long long)sink, 100.0 * (double)sink / (double)info->cells);
    printf("%6s %8s %12s  %s\n", "group", "period", "basin", "centre");
    for (uint32_t k = 0; k < info->groups && k < SHOWN_GROUPS; k++) {
        char centre[CM_MAX_DIM * CM_NUM_TEXT];
        cm_point_text(lat, g[k].centre, ", ", centre, sizeof centre);
        printf("%6u %8u %12llu  (%s)  anchor cell centre (", g[k].id, g[k].period,
               (unsigned long long)g[k].basin_cells, centre);
        print_cells(lat, g[k].anchor);
        printf(")\n");
    }
    if (info->groups > SHOWN_GROUPS)
        printf("... and %u smaller groups (cellmap export --groups lists all)\n",
               info->groups - SHOWN_GROUPS);
    printf("disk: %llu bytes (%.2f bytes/cell; cell pages %.2f bytes/cell)\n",
           (unsigned long long)info->file_bytes, (double)info->file_bytes / (double)info->cells,
           (double)info->page_bytes / (double)info->cells);
    printf("memory: %.1f MiB to hold every region (12 bytes/cell plus exits), %.1f MiB for "
           "the largest region (the least useful --mem)\n",
           (double)(info->cells * 12) / 1048576.0, (double)largest_region / 1048576.0);
}

static void print_json(const char *path, const cm_store_info *info, const cm_box *bounds,
                       const cm_group_info *g, uint64_t sink, const cm_attractor_set *att)
{
    json j;
    json_begin(&j, stdout, "info");
    json_str(&j, "file", path);
    json_int(&j, "format", info->version);
    json_str(&j, "tool_version", info->tool_version);
    cm_model m;
    char msg[512];
    cm_model_set set = {0};
    if (model_of_store(info, &set, &m, msg, sizeof msg) == CM_OK) {
        json_model(&j, &m);
        cm_model_release(&m);
    } else { /* a model this cellmap does not know: its name and parameters as written */
        json_str(&j, "model", info->model);
        json_raw(&j, "params", info->params);
    }
    json_lattice(&j, &info->lattice);
    json_str(&j, "made_by", info->command);
    json_uint(&j, "regions", info->regions);
    json_uint(&j, "cells", info->cells);
    json_box(&j, "box", &info->lattice, bounds);
    json_uint(&j, "box_cells", cm_box_cells(bounds));
    json_uint(&j, "sink_cells", sink);
    json_uint(&j, "file_bytes", info->file_bytes);
    json_uint(&j, "page_bytes", info->page_bytes);
    if (att) {
        attractor_json(&j, &info->lattice, att);
        attractor_json_groups(&j, g, info->groups, &info->lattice, att);
    } else {
        json_groups(&j, g, info->groups, &info->lattice);
    }
    json_end(&j);
}

int cmd_info(int argc, char **argv)
{
    cli c = {"info", argc, argv, 0, NULL, NULL};
    const char *path = NULL;
    int json = 0, err = 0;
    while (cli_next(&c) && !err) {
        if (strcmp(c.opt, "--help") == 0) {
            fputs(info_help, stdout);
            return EXIT_OK;
        } else if (cli_is(&c, "--json", false, &err)) {
            json = 1;
        } else if (c.opt[0] != '-' && !path) {
            path = c.opt;
        } else {
            err = cli_stray(&c);
        }
    }
    if (err)
        return err;
    if (!path)
        return cli_usage_error(&c, "which file? usage: cellmap info FILE.cmdb");
    if ((err = cli_input_check("info", path)) != EXIT_OK)
        return err;
    cm_store *s = NULL;
    cm_store_info info;
    cm_region *regions = NULL;
    cm_group_info *g = NULL;
    uint64_t sink = 0;
    char msg[1024];
    /* the file's records only: info loads no cluster */
    cm_status st = project_open_records(path, true, &s, &info, msg, sizeof msg);
    uint32_t shown = 0; /* the text lists the largest groups only: it reads only those */
    if (st == CM_OK) {
        shown = json || info.groups < SHOWN_GROUPS ? info.groups : SHOWN_GROUPS;
        regions = calloc(info.regions, sizeof *regions);
        g = calloc((size_t)shown + 1, sizeof *g);
        if (!regions || !g)
            st = cm_fail(CM_ENOMEM, msg, sizeof msg, "out of memory for %u regions and %u groups",
                         info.regions, info.groups);
    }
    if (st == CM_OK)
        st = cm_store_regions(s, regions, info.regions, msg, sizeof msg);
    if (st == CM_OK)
        st = json ? cm_store_groups(s, g, info.groups, &sink, msg, sizeof msg)
                  : cm_store_largest_groups(s, g, shown, &sink, msg, sizeof msg);
    cm_attractor_set att;
    memset(&att, 0, sizeof att);
    bool has_att = false;
    if (st == CM_OK) {
        const cm_status a = cm_store_get_attractors(s, info.lattice.dim, info.groups, &att, NULL,
                                                    msg, sizeof msg);
        has_att = a == CM_OK;
        st = a == CM_ENOTFOUND ? CM_OK : a;
    }
    cm_store_snapshot_end(s);
    if (st == CM_OK) {
        cm_box bounds = regions[0].box;
        uint64_t largest = 0;
        for (uint32_t k = 0; k < info.regions; k++) {
            cm_box_grow(&bounds, &regions[k].box);
            const uint64_t bytes = cm_region_bytes(&regions[k]);
            largest = bytes > largest ? bytes : largest;
        }
        if (json)
            print_json(path, &info, &bounds, g, sink, has_att ? &att : NULL);
        else
            print_text(path, &info, &bounds, g, sink, largest, has_att ? &att : NULL);
    } else {
        fprintf(stderr, "cellmap info: %s\n", msg);
    }
    free(regions);
    free(g);
    cm_attractors_free(&att);
    cm_store_close(s, msg, sizeof msg);
    return st == CM_OK ? EXIT_OK : EXIT_FAIL;
}
