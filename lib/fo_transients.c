/* lib/fo_transients.c - H, the extremal solution's perturbation map and the
 * convergence to a periodic solution (lib/fo_transients.h). */
#include "lib/fo_transients.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/numtext.h"
#include "lib/figure.h"
#include "lib/json.h"
#include "lib/param_grid.h"
#include "models/fo_continuation.h"
#include "models/fo_transients.h"

enum { H_SAMPLES = 600, EXTREMAL_POINTS = 60 };

static const double PI = 3.14159265358979323846;
static const cm_rgb black = {0, 0, 0}, red = {215, 48, 39}, blue = {69, 117, 180},
                    grey = {170, 170, 170};

static cm_chart chart_in(const chart_outputs *out, int k, int n, double xlo, double xhi,
                         double ylo, double yhi, const char *x_name, const char *y_name,
                         const char *title, const cm_series *s, int n_series,
                         const cm_chart_label *labels, int n_labels)
{
    const int h = out->height / n;
    return (cm_chart){out->width,    k < n - 1 ? h : out->height - (n - 1) * h,
                      {xlo, ylo},    {xhi, yhi},
                      x_name,        y_name,
                      title,         NULL,
                      s,             n_series,
                      figure_font(), 0,
                      labels,        n_labels};
}

static cm_status write_charts(const chart_outputs *out, const char *model, const char *params,
                              const cm_chart *charts, int n, char *msg, size_t msg_size)
{
    const cm_png_text texts[] = {{"Model", model}, {"Parameters", params}};
    return outfile_charts(out->png, charts, n, texts, 2, msg, msg_size);
}

/* ---- Fig. 2.5: H(t, Omega) --------------------------------------------- */

static cm_status run_h(const fo_transient_args *t, const char *model, const cm_params *base,
                       const chart_outputs *out, FILE *report, const char *params, char *msg,
                       size_t msg_size)
{
    const int n = t->n_omegas;
    double hmax[FO_H_MAX_CURVES], tmax[FO_H_MAX_CURVES];
    for (int k = 0; k < n; k++)
        hmax[k] = cm_fo_turn_hmax_at(t->omegas[k], &tmax[k]);
    if (out->json) {
        json j;
        json_begin(&j, stdout, "amplitude");
        param_base_json(&j, model, base);
        json_array(&j, "h");
        for (int k = 0; k < n; k++) {
            json_object(&j, NULL);
            json_num(&j, "Omega", t->omegas[k]);
            json_num(&j, "H_max", hmax[k]);
            json_num(&j, "t_max", tmax[k]);
            json_num(&j, "limit", 1 / (t->omegas[k] * t->omegas[k]));
            json_object_end(&j);
        }
        json_array_end(&j);
        json_end(&j);
    }
    for (int k = 0; k < n && report; k++) {
        char at[64] = "at t -> 0";
        if (tmax[k] > 0)
            snprintf(at, sizeof at, "at t = %.6g", tmax[k]);
        fprintf(report, "Omega = %s: H_max = %.6g %s (1/Omega^2 = %.6g, (2.30))\n",
                CM_NUM(t->omegas[k]), hmax[k], at, 1 / (t->omegas[k] * t->omegas[k]));
    }
    double *v = malloc(sizeof(double) * (size_t)n * (2 * H_SAMPLES + 8));
    if (!v)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for H");
    outfile o;
    bool ok = !out->csv || outfile_begin(out->csv, &o, msg, msg_size) == CM_OK;
    if (ok && out->csv)
        fprintf(o.f, "Omega,t,H\n");
    cm_series series[FO_H_MAX_CURVES][3];
    cm_chart_label labels[FO_H_MAX_CURVES];
    cm_chart charts[FO_H_MAX_CURVES];
    char titles[FO_H_MAX_CURVES][200], names[FO_H_MAX_CURVES][64];
    for (int k = 0; k < n; k++) {
        const double w = t->omegas[k], end = PI / w;
        double *x = v + (size_t)k * (2 * H_SAMPLES + 8), *y = x + H_SAMPLES, *e = y + H_SAMPLES;
        for (int i = 0; i < H_SAMPLES; i++) {
            x[i] = (i + 0.5) * end / H_SAMPLES, y[i] = cm_fo_turn_h(x[i], w);
            if (ok && out->csv)
                fprintf(o.f, "%.17g,%.17g,%.17g\n", w, x[i], y[i]);
        }
        /* 1/Omega^2 across, and the maximum */
        e[0] = 0, e[1] = end, e[2] = e[3] = 1 / (w * w), e[4] = tmax[k], e[5] = hmax[k];
        series[k][0] = (cm_series){CM_SERIES_LINE, e, e + 2, 2, blue, 1};
        series[k][1] = (cm_series){CM_SERIES_LINE, x, y, H_SAMPLES, black, 2};
        series[k][2] = (cm_series){CM_SERIES_POINTS, e + 4, e + 5, 1, red, 9};
        snprintf(names[k], sizeof names[k], "H_max = %.4g", hmax[k]);
        labels[k] = (cm_chart_label){tmax[k], hmax[k], names[k]};
        snprintf(titles[k], sizeof titles[k],
                 "H(t, Omega) of (2.29) at Omega = %s (black), 1/Omega^2 (blue), H_max (red)",
                 CM_NUM(w));
        const double top = 1.25 * fmax(hmax[k], 1 / (w * w));
        charts[k] = chart_in(out, k, n, 0, end, -top, top, "t", "H", titles[k], series[k], 3,
                             &labels[k], 1);
    }
    if (out->csv)
        ok = outfile_end(&o, ok, msg, msg_size) == CM_OK && ok;
    if (ok && out->png)
        ok = write_charts(out, model, params, charts, n, msg, msg_size) == CM_OK;
    free(v);
    return ok ? CM_OK : CM_EIO;
}

/* ---- Fig. 2.10: the perturbation map of the extremal solution ---------- */

static cm_status run_extremal(const fo_transient_args *t, const char *model,
                              const cm_params *base, const cm_fo *fo, const chart_outputs *out,
                              FILE *report, const char *params, char *msg, size_t msg_size)
{
    enum { N = EXTREMAL_POINTS };
    double eps[N], next[N], thesis[N], ratio[N], line_x[2], line_y[2], two[2] = {-2, -2};
    int lost = 0;
    for (int i = 0; i < N; i++) {
        eps[i] = t->eps_max * (i + 1) / N;
        next[i] = cm_fo_extremal_next(fo, eps[i]);
        thesis[i] = eps[i] - 2 * eps[i] * eps[i];
        ratio[i] = (next[i] - eps[i]) / (eps[i] * eps[i]);
        lost += isnan(next[i]);
    }
    if (out->json) {
        json j;
        json_begin(&j, stdout, "amplitude");
        param_base_json(&j, model, base);
        json_nums(&j, "eps", eps, N);
        json_nums(&j, "next", next, N);
        json_num(&j, "coefficient", ratio[0]);
        json_end(&j);
    }
    if (report)
        fprintf(report,
                "the extremal asymmetric solution (x0 = 1 + S) pushed into the sticking region "
                "by eps: (eps' - eps)/eps^2 = %.6g at eps = %.3g, %.6g at %.3g (the thesis' "
                "second-order map eps' = eps - 2 eps^2: -2)%s\n",
                ratio[0], eps[0], ratio[N - 1], eps[N - 1],
                lost ? "; some perturbations never stuck again" : "");
    outfile o;
    bool ok = !out->csv || outfile_begin(out->csv, &o, msg, msg_size) == CM_OK;
    if (ok && out->csv) {
        fprintf(o.f, "eps,next,thesis_next,ratio\n");
        for (int i = 0; i < N; i++)
            fprintf(o.f, "%.17g,%.17g,%.17g,%.17g\n", eps[i], next[i], thesis[i], ratio[i]);
        ok = outfile_end(&o, true, msg, msg_size) == CM_OK;
    }
    if (!ok || !out->png)
        return ok ? CM_OK : CM_EIO;
    line_x[0] = 0, line_x[1] = t->eps_max, line_y[0] = 0, line_y[1] = t->eps_max;
    const cm_series map[] = {
        {CM_SERIES_LINE, line_x, line_y, 2, grey, 1},
        {CM_SERIES_LINE, eps, thesis, N, red, 2},
        {CM_SERIES_POINTS, eps, next, N, black, 6},
    };
    const cm_series coef[] = {
        {CM_SERIES_LINE, line_x, two, 2, red, 2},
        {CM_SERIES_POINTS, eps, ratio, N, black, 6},
    };
    double lo = -2, hi = -2;
    for (int i = 0; i < N; i++)
        if (isfinite(ratio[i]))
            lo = fmin(lo, ratio[i]), hi = fmax(hi, ratio[i]);
    const double pad = fmax(0.05, 0.2 * (hi - lo));
    const cm_chart charts[2] = {
        chart_in(out, 0, 2, 0, t->eps_max, 0, t->eps_max, "eps_i", "eps_(i+1)",
                 "the perturbation map of the extremal asymmetric solution: simulated (black), "
                 "eps - 2 eps^2 (red), identity (grey)",
                 map, 3, NULL, 0),
        chart_in(out, 1, 2, 0, t->eps_max, lo - pad, hi + pad, "eps_i",
                 "(eps_(i+1) - eps_i)/eps_i^2",
                 "its second-order coefficient: simulated (black), the thesis' -2 (red)", coef,
                 2, NULL, 0),
    };
    return write_charts(out, model, params, charts, 2, msg, msg_size);
}

/* ---- Fig. 2.11: convergence to a periodic solution --------------------- */

/* The least-squares slope of log(err) over n where err is above the
 * rounding floor. */
static double decay_fit(const double *err, int n)
{
    double sn = 0, sy = 0, snn = 0, sny = 0, k = 0;
    for (int i = 0; i <= n; i++)
        if (err[i] > 1e-12) {
            const double y = log(err[i]);
            sn += i, sy += y, snn += (double)i * i, sny += i * y, k++;
        }
    return k > 2 ? (k * sny - sn * sy) / (k * snn - sn * sn) : NAN;
}

static cm_status run_converge(const fo_transient_args *t, const char *model,
                              const cm_params *base, const cm_fo *fo, const chart_outputs *out,
                              FILE *report, const char *params, char *msg, size_t msg_size)
{
    const int n = t->periods;
    double *v = malloc(sizeof(double) * 4 * ((size_t)n + 1));
    if (!v)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d periods", n);
    double *err = v, *ns = v + n + 1, *lg = ns + n + 1, *env = lg + n + 1;
    const double z0[2] = {1 + 0.9 * fo->S0, 0}; /* the thesis' start, as the diagram's */
    cm_fo_convergence c;
    if (!cm_fo_converge(fo, z0, n, n, err, &c)) {
        free(v);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the simulation from (%s, 0) does not settle on a periodic solution in "
                       "%d periods (or the motion was lost): try more --converge periods",
                       CM_NUM(z0[0]), n);
    }
    const double fit = decay_fit(err, n), rate = log(c.mult_max);
    double scale = 0; /* the envelope C |lambda|^n over every error */
    for (int i = 0; i <= n; i++)
        if (err[i] > 1e-12)
            scale = fmax(scale, err[i] / pow(c.mult_max, i));
    const double t2 = c.mult_arg > 0 ? 2 * PI / c.mult_arg : INFINITY;
    if (out->json) {
        json j;
        json_begin(&j, stdout, "amplitude");
        param_base_json(&j, model, base);
        json_nums(&j, "start", z0, 2);
        json_nums(&j, "z_star", c.z_star, 2);
        json_num(&j, "mult_max", c.mult_max);
        json_num(&j, "mult_arg", c.mult_arg);
        json_num(&j, "decay_fit", fit);
        json_num(&j, "secondary_periods", t2);
        json_end(&j);
    }
    if (report)
        fprintf(report,
                "from (%s, 0) to (%.9g, %.9g) on the section: leading multiplier |lambda| = "
                "%.6g, arg %.4g; the relative error decays by %.6g per period (fit) against "
                "log|lambda| = %.6g; the transients' secondary period 2 pi/arg = %.4g periods "
                "(2.86)\n",
                CM_NUM(z0[0]), c.z_star[0], c.z_star[1], c.mult_max, c.mult_arg, fit, rate, t2);
    for (int i = 0; i <= n; i++) {
        ns[i] = i;
        lg[i] = err[i] > 0 ? log10(err[i]) : NAN;
        env[i] = log10(scale) + i * log10(c.mult_max);
    }
    outfile o;
    bool ok = !out->csv || outfile_begin(out->csv, &o, msg, msg_size) == CM_OK;
    if (ok && out->csv) {
        fprintf(o.f, "n,relative_error,envelope\n");
        for (int i = 0; i <= n; i++)
            fprintf(o.f, "%d,%.17g,%.17g\n", i, err[i], pow(10, env[i]));
        ok = outfile_end(&o, true, msg, msg_size) == CM_OK;
    }
    if (ok && out->png) {
        double lo = 0, hi = -INFINITY;
        for (int i = 0; i <= n; i++)
            if (isfinite(lg[i]))
                lo = fmin(lo, lg[i]), hi = fmax(hi, fmax(lg[i], env[i]));
        const cm_series s[] = {{CM_SERIES_LINE, ns, lg, (size_t)n + 1, black, 1},
                               {CM_SERIES_LINE, ns, env, (size_t)n + 1, red, 2}};
        char title[300];
        snprintf(title, sizeof title,
                 "convergence to the periodic solution: relative error (black), |lambda_max|^n "
                 "envelope (red), |lambda_max| = %.5g",
                 c.mult_max);
        const cm_chart chart = chart_in(out, 0, 1, 0, n, lo - 0.5, hi + 0.5, "periods",
                                        "log10 relative error", title, s, 2, NULL, 0);
        ok = write_charts(out, model, params, &chart, 1, msg, msg_size) == CM_OK;
    }
    free(v);
    return ok ? CM_OK : CM_EIO;
}

cm_status fo_transient_run(const fo_transient_args *t, const char *model, const cm_params *base,
                           const chart_outputs *out, FILE *report, char *msg, size_t msg_size)
{
    char params[400];
    cm_params_format(base, params, sizeof params);
    cm_fo fo;
    cm_fo_init(&fo, cm_params_get(base, "S"), cm_params_get(base, "S0"),
               cm_params_get(base, "Omega"), cm_params_get(base, "phi"));
    switch (t->kind) {
    case FO_H:
        if (t->n_omegas < 1 || t->n_omegas > FO_H_MAX_CURVES)
            return cm_fail(CM_EINVAL, msg, msg_size, "H takes 1..%d frequencies",
                           FO_H_MAX_CURVES);
        for (int k = 0; k < t->n_omegas; k++)
            if (!(t->omegas[k] > 0 && t->omegas[k] < 100))
                return cm_fail(CM_EINVAL, msg, msg_size,
                               "Omega = %s: the frequencies must be in (0, 100)",
                               CM_NUM(t->omegas[k]));
        return run_h(t, model, base, out, report, params, msg, msg_size);
    case FO_EXTREMAL:
        if (!(t->eps_max > 0 && t->eps_max < fo.S))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "eps_max = %s: the perturbations must stay in the sticking region, "
                           "0 < eps < S = %s",
                           CM_NUM(t->eps_max), CM_NUM(fo.S));
        return run_extremal(t, model, base, &fo, out, report, params, msg, msg_size);
    case FO_CONVERGE:
        if (t->periods < 10 || t->periods > 1000000)
            return cm_fail(CM_EINVAL, msg, msg_size, "periods: %d is not in 10..1000000",
                           t->periods);
        return run_converge(t, model, base, &fo, out, report, params, msg, msg_size);
    default:
        return cm_fail(CM_EINVAL, msg, msg_size, "no such analysis (%d)", t->kind);
    }
}
