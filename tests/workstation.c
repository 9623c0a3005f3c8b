/* workstation: the command's work done by a C program through libcellmap's
 * experimental section alone (built with pkg-config against the installed
 * library by tests/workstation_test.sh, which compares what it writes with
 * what the command writes, row for row and byte for byte):
 *   c_split.cmdb    solve --db --split 2x2
 *   c_resumed.cmdb  the same solve cancelled after its first join, then
 *                   resumed (solve --resume)
 *   c_partial.cmdb  a copy of the cancelled file, for the command to resume
 *   c_ext.cmdb      solve --db --extend 3
 *   c_explore.cmdb  an explore session: a view, 20 pans of 10 %, then
 *   c_view.png      render of the view
 *   c_labels.npy    export --labels of c_split.cmdb
 *   c_added.cmdb    c_ext's first tile solved alone, then a box added
 *                   beside it (explore's `view` on the file)
 *   c_extended.cmdb that tile extended 3 times from tiles of its size
 *                   (explore's `view` of the tile, then `extend auto 3`)
 *   c_NAME.csv/png  the analysis commands (stability, partition, amplitude,
 *                   horseshoe, escape, simulate, bifurcation and its runs,
 *                   lyapunov, sweep, continue and its events), as
 *                   tests/workstation_analysis.py does them
 * usage: workstation (in the directory to write in) */
#define CELLMAP_EXPERIMENTAL
#include <cellmap/cellmap.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PD "alpha=0.078,beta=0,P=0.007,D=0.02"

static void must(cm_status st, const char *what, const char *msg)
{
    if (st != CM_OK) {
        fprintf(stderr, "workstation: %s: %s (%s)\n", what, msg, cm_status_name(st));
        exit(1);
    }
}

/* Cancels a solve at its first report after some work (the first join). */
static int cancel_after_first(void *user, double fraction)
{
    (void)user;
    return fraction > 0 && fraction < 1;
}

static int copy_file(const char *from, const char *to)
{
    FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
    char buf[1 << 16];
    size_t n;
    int ok = in && out;
    while (ok && (n = fread(buf, 1, sizeof buf, in)) > 0)
        ok = fwrite(buf, 1, n, out) == n;
    if (in)
        fclose(in);
    if (out)
        ok = fclose(out) == 0 && ok;
    return ok;
}

/* The analysis command NAME's outputs c_NAME.csv and c_NAME.png. */
static cm_analysis outputs(const char *name, char files[2][64], int png)
{
    snprintf(files[0], 64, "c_%s.csv", name);
    snprintf(files[1], 64, "c_%s.png", name);
    return (cm_analysis){.csv = files[0], .png = png ? files[1] : NULL};
}

static void analyses(void)
{
    char msg[1024], f[2][64];
    cm_analysis a = outputs("stability", f, 1);
    must(cm_analysis_stability(&a, &(cm_axis){"P", 0.007, 0.02, 50},
                               &(cm_axis){"alpha", 0.1, 1, 20}, msg, sizeof msg),
         "stability", msg);
    a = outputs("partition", f, 1);
    a.params = "a=1.3,b=0.66";
    must(cm_analysis_partition(&a, msg, sizeof msg), "partition", msg);
    a = outputs("amplitude", f, 1);
    must(cm_analysis_amplitude(&a, &(cm_axis){"Omega", 0.2, 2, 20}, 50, 0, msg, sizeof msg),
         "amplitude", msg);
    cm_horseshoe_options ho = cm_horseshoe_defaults();
    ho.m0 = 1, ho.m1 = 3, ho.periods = 6;
    a = outputs("horseshoe", f, 1);
    must(cm_analysis_horseshoe(&a, &ho, msg, sizeof msg), "horseshoe", msg);
    cm_escape_options eo = cm_escape_defaults();
    eo.cells = 1000, eo.ensemble = 1000;
    a = outputs("escape", f, 1);
    must(cm_analysis_escape(&a, &eo, msg, sizeof msg), "escape", msg);
    cm_simulate_options so = cm_simulate_defaults();
    so.x = 1, so.periods = 5;
    a = outputs("simulate", f, 1);
    must(cm_analysis_simulate(&a, &so, msg, sizeof msg), "simulate", msg);
    cm_bifurcation_options bo = cm_bifurcation_defaults();
    bo.sweep = (cm_axis){"S", 0.1, 0.3, 4};
    bo.runs = 2, bo.transient = 20, bo.record = 5, bo.runs_csv = "c_bifurcation_runs.csv";
    a = outputs("bifurcation", f, 1);
    must(cm_analysis_bifurcation(&a, &bo, msg, sizeof msg), "bifurcation", msg);
    cm_lyapunov_options lo = cm_lyapunov_defaults();
    lo.x = (cm_axis){"Omega", 0.4, 0.6, 3}, lo.y = (cm_axis){"S", 0.1, 0.2, 3}, lo.periods = 50;
    a = outputs("lyapunov", f, 1);
    must(cm_analysis_lyapunov(&a, &lo, msg, sizeof msg), "lyapunov", msg);
    const cm_sweep_options wo = {.name = "P",
                                 .values = (const double[]){0.006, 0.007},
                                 .n_values = 2,
                                 .region = "0:100,-10:10",
                                 .cells = (const int64_t[]){50, 50},
                                 .n_cells = 2,
                                 .fractions = "c_sweep_fractions.csv",
                                 .keep = "c_kept"};
    a = outputs("sweep", f, 1);
    must(cm_analysis_sweep(&a, &wo, msg, sizeof msg), "sweep", msg);
    cm_continue_options co = cm_continue_defaults();
    co.vary = "S", co.lo = 0.02, co.hi = 0.4, co.max_points = 50;
    co.events = "c_continue_events.csv";
    a = outputs("continue", f, 1);
    must(cm_analysis_continue(&a, &co, msg, sizeof msg), "continue", msg);
    cm_equilibria_options eqo = cm_equilibria_defaults();
    eqo.b.from = (const double[]){1, 0.1, 0.2, 0.25}, eqo.b.n_from = 4;
    eqo.b.name = "xi", eqo.b.lo = 3, eqo.b.hi = 15;
    eqo.curve = &(cm_axis){"zeta", 20, 21, 2};
    a = outputs("equilibria", f, 0);
    must(cm_analysis_equilibria(&a, &eqo, msg, sizeof msg), "equilibria", msg);
    cm_periodic_options po = cm_periodic_defaults();
    po.b.from = (const double[]){1.05, 0.2, 0.27}, po.b.n_from = 3, po.settle = 100;
    po.b.name = "xi", po.b.lo = 2.9, po.b.hi = 4.1, po.b.direction = 1, po.cascade = 2;
    a = outputs("periodic", f, 0);
    a.params = "xi=2.9";
    must(cm_analysis_periodic(&a, &po, msg, sizeof msg), "periodic", msg);
    cm_exponents_options xo = cm_exponents_defaults();
    xo.start[0] = 1, xo.start[1] = 0.1, xo.start[2] = 0.2, xo.start[3] = 0.3, xo.n_from = 4;
    xo.time = 20, xo.transient = 5;
    a = outputs("exponents", f, 1);
    a.params = "xi=4.8";
    cm_exponents ex;
    must(cm_analysis_exponents(&a, &xo, &ex, msg, sizeof msg), "exponents", msg);
    if (ex.count != 4 || !(ex.lambda[0] > 0 && ex.lambda[3] < -30)) {
        fprintf(stderr, "exponents: %d, %g .. %g\n", ex.count, ex.lambda[0], ex.lambda[3]);
        exit(1);
    }
    cm_series_options so2 = cm_series_defaults();
    so2.time = 50, so2.dt = 0.05, so2.of = "tau", so2.time_unit = 1e-3;
    so2.spectrum_csv = "c_series_spectrum.csv";
    a = outputs("series", f, 1);
    a.model = "chip-bue";
    must(cm_analysis_series(&a, &so2, msg, sizeof msg), "series", msg);
    cm_embedding_options mo = cm_embedding_defaults();
    mo.of = "tau2", mo.start[0] = 1, mo.start[1] = 0.1, mo.start[2] = 0.2, mo.start[3] = 0.3;
    mo.n_from = 4, mo.time = 200, mo.transient = 10, mo.dt = 0.005, mo.steps = 10;
    a = outputs("embedding", f, 1);
    a.params = "xi=4.8";
    cm_embedding em;
    must(cm_analysis_embedding(&a, &mo, &em, msg, sizeof msg), "embedding", msg);
    if (em.embedding_dim != 3 || !(em.lambda > 0.2 && em.lambda < 0.5)) {
        fprintf(stderr, "embedding: dimension %d, lambda %g\n", em.embedding_dim, em.lambda);
        exit(1);
    }
    cm_measure_options mso = cm_measure_defaults();
    mso.file = "c_split.cmdb", mso.to = "c_resumed.cmdb", mso.window = "0:100,-40:40";
    mso.samples = 2000;
    a = outputs("measure", f, 1);
    cm_measures ms;
    must(cm_analysis_measure(&a, &mso, &ms, msg, sizeof msg), "measure", msg);
    if (ms.computed == 0 || ms.computed > ms.cells || !(ms.alpha > 0) || ms.sampled == 0 ||
        ms.sampled_as_labelled > ms.sampled) {
        fprintf(stderr, "measure: %llu of %llu cells, alpha %g\n",
                (unsigned long long)ms.computed, (unsigned long long)ms.cells, ms.alpha);
        exit(1);
    }
}

int main(void)
{
    char msg[1024];
    const cm_grid grid = {2, {0, -40}, {500, 40}, {200, 100}};
    const cm_db_options split = {.split = {2, 2}, .threads = 2};
    must(cm_db_create(NULL, "microchaos-pd", PD, &grid, "c_split.cmdb", &split, msg, sizeof msg),
         "create", msg);

    cm_db_options cancelled = split;
    cancelled.progress = cancel_after_first;
    const cm_status st =
        cm_db_create(NULL, "microchaos-pd", PD, &grid, "c_resumed.cmdb", &cancelled, msg,
                     sizeof msg);
    if (st != CM_ECANCELED) {
        fprintf(stderr, "workstation: the cancelled solve gave %s\n", cm_status_name(st));
        return 1;
    }
    if (!copy_file("c_resumed.cmdb", "c_partial.cmdb"))
        return fprintf(stderr, "workstation: cannot copy the partial file\n"), 1;
    must(cm_db_resume(NULL, "microchaos-pd", PD, &grid, "c_resumed.cmdb", &split, msg,
                      sizeof msg),
         "resume", msg);

    const cm_db_options extend = {.extend = 3, .threads = 2};
    const cm_grid tile = {2, {0, -40}, {100, 40}, {100, 100}};
    must(cm_db_create(NULL, "microchaos-pd", PD, &tile, "c_ext.cmdb", &extend, msg, sizeof msg),
         "create --extend", msg);

    const cm_session_options so = {.model = "microchaos-pd",
                                   .params = PD,
                                   .cell_size = {0.5, 0.08},
                                   .threads = 2};
    cm_session *s = NULL;
    must(cm_session_open("c_explore.cmdb", &so, &s, msg, sizeof msg), "session", msg);
    must(cm_session_view(s, (double[2]){0, -4}, (double[2]){50, 4}, NULL, msg, sizeof msg),
         "view", msg);
    for (int k = 0; k < 20; k++) { /* pan right 10% */
        double lo[2], hi[2];
        must(cm_session_bounds(s, lo, hi), "bounds", "");
        must(cm_session_pan(s, 0, 10 * ((hi[0] - lo[0]) / 100), NULL, msg, sizeof msg), "pan",
             msg);
    }
    const cm_figure_options view = {.png = "c_view.png",
                                    .layers = CM_FIGURE_BASIN | CM_FIGURE_ATTRACTORS};
    must(cm_session_figure(s, &view, msg, sizeof msg), "render", msg);
    must(cm_session_close(s, msg, sizeof msg), "close", msg);

    must(cm_db_export("c_split.cmdb", NULL, NULL, "c_labels.npy", NULL, 0, msg, sizeof msg),
         "export", msg);
    const cm_db_options plain = {.threads = 2};
    must(cm_db_create(NULL, "microchaos-pd", PD, &tile, "c_added.cmdb", &plain, msg, sizeof msg),
         "create a tile", msg);
    uint64_t added = 0;
    must(cm_db_add_box("c_added.cmdb", (double[2]){100, -40}, (double[2]){200, 40}, &plain,
                       &added, msg, sizeof msg),
         "add a box", msg);
    if (added != 100 * 100)
        return fprintf(stderr, "workstation: add_box computed %llu cells\n",
                       (unsigned long long)added), 1;
    must(cm_db_create(NULL, "microchaos-pd", PD, &tile, "c_extended.cmdb", &plain, msg,
                      sizeof msg),
         "create a tile", msg);
    int steps = 0;
    must(cm_db_extend("c_extended.cmdb", (double[2]){0, -40}, (double[2]){100, 40}, 3, &plain,
                      &steps, msg, sizeof msg),
         "extend", msg);
    if (steps != 3)
        return fprintf(stderr, "workstation: extend did %d steps\n", steps), 1;
    analyses();
    return 0;
}
