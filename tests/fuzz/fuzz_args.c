/* libFuzzer target: the command-line parsers. The first byte chooses one,
 * the rest is its text (for `solve`: its arguments, one per line):
 *   0 ranges, 1 counts, 2 numbers, 3 sizes, 4 integers and reals, 5 layers
 *   and PNG modes, 6 model parameters (cm_model_create, every model), 7 a
 *   --region/--cells lattice, 8 a file's parameters as JSON (model_of_store),
 *   9 solve's whole command line, checked as solve checks it before work.
 * solve's parser is static: its file is compiled into this target. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/registry.h"
#include "src/cmd_solve.c"

static void parse_text(unsigned which, const char *text)
{
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM], v[64];
    int64_t counts[CM_MAX_DIM], i64;
    uint64_t bytes;
    unsigned layers;
    int n = 0, indexed;
    char bad[64];
    switch (which) {
    case 0:
        parse_ranges(text, lo, hi, &n, CM_MAX_DIM);
        break;
    case 1:
        parse_counts(text, counts, &n, CM_MAX_DIM);
        break;
    case 2:
        parse_doubles(text, v, &n, 64);
        break;
    case 3:
        parse_bytes(text, &bytes);
        break;
    case 4:
        parse_int64(text, &i64);
        parse_double(text, v);
        break;
    default:
        parse_layers(text, &layers, bad, sizeof bad);
        parse_png_mode(text, &indexed);
    }
}

static void create_models(const char *text)
{
    const char *texts[1] = {text};
    char msg[512];
    for (size_t k = 0; k < cm_model_count(); k++) {
        cm_model m;
        if (cm_model_create(cm_model_at(k)->name, texts, 1, &m, msg, sizeof msg) == CM_OK)
            cm_model_release(&m);
    }
}

static void build_lattice(const char *text)
{
    const char *comma = strchr(text, '\n');
    lattice_opts lo;
    memset(&lo, 0, sizeof lo);
    char region[256];
    snprintf(region, sizeof region, "%.*s", comma ? (int)(comma - text) : 255, text);
    lo.region_text = region;
    if (comma && !parse_counts(comma + 1, lo.cells, &lo.n_cells, CM_MAX_DIM))
        lo.n_cells = 0;
    cm_model m;
    char msg[512];
    if (cm_model_create("microchaos-pd", NULL, 0, &m, msg, sizeof msg) != CM_OK)
        abort();
    cli c = {"fuzz", 0, NULL, 0, NULL, NULL};
    cm_lattice lat;
    cm_box box;
    lattice_opts_build(&c, &lo, &m, NULL, &lat, &box);
    cm_model_release(&m);
}

static void model_from_json(const char *text)
{
    cm_store_info info;
    memset(&info, 0, sizeof info);
    snprintf(info.params, sizeof info.params, "%s", text);
    char msg[512];
    for (size_t k = 0; k < cm_model_count(); k++) {
        snprintf(info.model, sizeof info.model, "%s", cm_model_at(k)->name);
        cm_model m;
        cm_model_set set = {0};
        if (model_of_store(&info, &set, &m, msg, sizeof msg) == CM_OK)
            cm_model_release(&m);
    }
}

/* solve's arguments as solve checks them, up to the work. */
static void solve_line(char *text)
{
    char *argv[34] = {"solve"};
    int argc = 1;
    for (char *p = text; p && argc < 33; argc++) {
        argv[argc] = p;
        p = strchr(p, '\n');
        if (p)
            *p++ = '\0';
    }
    cli c = {"solve", argc, argv, 0, NULL, NULL};
    solve_args a;
    memset(&a, 0, sizeof a);
    a.mo.name = "microchaos-pd";
    if (parse_solve(&c, &a) != 0)
        return;
    cm_model m;
    if (model_opts_build(&c, &a.mo, &m) != EXIT_OK)
        return;
    cm_lattice lat;
    cm_box box, bounds;
    if (make_lattice(&c, &a, &m, &lat, &box) == EXIT_OK &&
        make_bounds(&c, &a, &lat, &box, &bounds) == EXIT_OK && a.png.path)
        check_basin_png("solve", &a.png, &m, &lat, &box);
    cm_model_release(&m);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 2048)
        return 0;
    char *text = malloc(size);
    memcpy(text, data + 1, size - 1);
    text[size - 1] = '\0';
    switch (data[0] % 10) {
    case 6:
        create_models(text);
        break;
    case 7:
        build_lattice(text);
        break;
    case 8:
        model_from_json(text);
        break;
    case 9:
        solve_line(text);
        break;
    default:
        parse_text(data[0] % 10, text);
    }
    free(text);
    return 0;
}
