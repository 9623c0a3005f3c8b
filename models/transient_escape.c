/* models/transient_escape.c - the transient chaos of the 1-D micro-chaos
 * map with Coulomb friction (thesis 4.3). docs/models.md 4.1. */
#include "models/transient_escape.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

double cm_te_c_of_I0(double a, double b, double I0)
{
    return (I0 + a - b) * (a - 1) / a;
}

/* The root in (0, 1) of 1/(1 - a^-D) = C^-D (4.32) by bisection to 1e-15;
 * NaN where there is none (C outside (0, 1), or 1/C <= a/(a - 1)). */
static double dimension(double a, double C)
{
    if (!(C > 0 && C < 1 && 1 / C > a / (a - 1)))
        return NAN;
    double lo = 1e-9, hi = 1; /* g > 0 at lo, < 0 at hi */
    for (int it = 0; it < 200 && hi - lo > 1e-15; it++) {
        const double mid = 0.5 * (lo + hi);
        const double g = 1 / (1 - pow(a, -mid)) - pow(C, -mid);
        if (g > 0)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

bool cm_te_setup(double a, double b, double c, cm_te *t, char *why, size_t why_size)
{
    t->a = a, t->b = b, t->c = c;
    t->x0 = c / (a - 1);
    t->rep_hi = a - c;
    t->I0 = a * c / (a - 1) - (a - b);
    t->rep_len = t->rep_hi - t->x0;
    const double x1 = (b + c) / (a - 1); /* of level 1: f(a - c) <= a - c iff x1 >= a - c */
    const char *problem = !(a > 1)                   ? "a must exceed 1"
                          : !(b > 0 && c > 0)        ? "b and c must be positive"
                          : !(t->I0 > 0)             ? "|I0| = a c/(a - 1) - (a - b) must be positive"
                          : !(t->rep_len > 0)        ? "I_rep = [c/(a - 1), a - c] is empty"
                          : !(t->x0 < 1)             ? "x0* = c/(a - 1) must lie below 1"
                          : !(t->rep_hi < 2)         ? "a - c must lie below 2"
                          : !(x1 >= t->rep_hi)
                              ? "the fixed point (b + c)/(a - 1) lies inside I_rep, which f then "
                                "does not map into itself"
                              : NULL;
    if (problem) {
        snprintf(why, why_size, "%s (thesis 4.3 takes one positive fixed point in I_rep)",
                 problem);
        return false;
    }
    t->F = (a * t->rep_len - b) / (a * a);
    t->C[0] = 1 + b / (a * (t->I0 - b));
    t->C[1] = 1 - (a * t->I0 + b) / (a * b);
    t->a_crit = b / t->rep_len;
    t->border = !(t->F > 0);
    for (int i = 0; i < 2; i++) {
        t->D0[i] = t->border ? 0 : dimension(a, t->C[i]);
        t->kappa[i] = (1 - t->D0[i]) * log(a);
        t->n_esc[i] = 1 / (1 - exp(-t->kappa[i]));
    }
    return true;
}

double cm_te_map(const cm_te *t, double x)
{
    const double dead = t->c / t->a;
    if (x > dead)
        return t->a * x - t->b * floor(x) - t->c;
    if (x < -dead)
        return t->a * x - t->b * ceil(x) + t->c; /* Int rounds toward zero */
    return 0;
}

long cm_te_escape_number(const cm_te *t, double x, long cap)
{
    for (long n = 0; n <= cap; n++) {
        if (x < t->x0)
            return n;
        x = cm_te_map(t, x);
    }
    return -1;
}

double cm_te_grid_mean(const cm_te *t, long n)
{
    double sum = 0;
    for (long i = 0; i < n; i++)
        sum += (double)cm_te_escape_number(t, t->x0 + ((double)i + 0.5) * t->rep_len / (double)n,
                                           100000);
    return sum / (double)n;
}

static int compare_doubles(const void *p, const void *q)
{
    const double a = *(const double *)p, b = *(const double *)q;
    return (a > b) - (a < b);
}

/* The index of the partition point nearest to x (points sorted). */
static long nearest(const double *p, long n, double x)
{
    long lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        const long mid = (lo + hi) / 2;
        if (p[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    return fabs(p[hi] - x) < fabs(p[lo] - x) ? hi : lo;
}

/* The Markov partition: x0*, 1, and the orbit of a - c while it stays in
 * I_rep (the images of the breakpoints: f(1-) = a - c, f(1) < x0*, and x0*
 * is fixed). Sorted, without repeats; its size into *n, or false. */
static bool partition_points(const cm_te *t, long max_partition, double **out, long *n)
{
    double *p = malloc((size_t)(max_partition + 3) * sizeof *p);
    if (!p)
        return false;
    long k = 0;
    p[k++] = t->x0;
    if (t->rep_hi > 1)
        p[k++] = 1;
    double o = t->rep_hi;
    while (o >= t->x0) {
        if (k == max_partition + 2) {
            free(p);
            return false;
        }
        p[k++] = o;
        o = cm_te_map(t, o);
    }
    qsort(p, (size_t)k, sizeof *p, compare_doubles);
    long m = 0;
    for (long i = 0; i < k; i++)
        if (m == 0 || p[i] > p[m - 1])
            p[m++] = p[i];
    *out = p;
    *n = m;
    return true;
}

bool cm_te_exact_mean(const cm_te *t, long max_partition, double *mean, long *partition)
{
    double *p;
    long np;
    if (!partition_points(t, max_partition, &p, &np))
        return false;
    const long n = np - 1; /* intervals [p_i, p_i+1] */
    long *from = malloc((size_t)n * sizeof *from), *to = malloc((size_t)n * sizeof *to);
    double *m = malloc((size_t)n * sizeof *m), *prefix = malloc((size_t)(n + 1) * sizeof *prefix);
    bool ok = from && to && m && prefix;
    /* each interval's image: the intervals from[i]..to[i]-1 (its part below
     * x0* escapes); the branch is the left end's, with f's left limit at 1 */
    for (long i = 0; i < n && ok; i++) {
        const double lo = cm_te_map(t, p[i]);
        const double hi = t->a * p[i + 1] - t->b * floor(p[i]) - t->c;
        from[i] = lo < t->x0 ? 0 : nearest(p, np, lo);
        to[i] = hi < t->x0 ? 0 : nearest(p, np, hi);
        /* Markov: the image's ends are partition points (x0* to rounding) */
        ok = (lo < t->x0 || fabs(p[from[i]] - lo) < 1e-12) &&
             (hi < t->x0 || fabs(p[to[i]] - hi) < 1e-12);
        m[i] = p[i + 1] - p[i];
    }
    /* m = |J| + (1/a) sum of m over the image, to a fixed point: the
     * iteration contracts by exp(-kappa), the survival per step */
    double change = 1;
    for (int it = 0; ok && it < 100000 && change > 1e-16; it++) {
        prefix[0] = 0;
        for (long i = 0; i < n; i++)
            prefix[i + 1] = prefix[i] + m[i];
        change = 0;
        double total = 0;
        for (long i = 0; i < n; i++) {
            const double next = (p[i + 1] - p[i]) + (prefix[to[i]] - prefix[from[i]]) / t->a;
            change = fmax(change, fabs(next - m[i]));
            m[i] = next;
            total += next;
        }
        change /= total;
    }
    if (ok) {
        double sum = 0;
        for (long i = 0; i < n; i++)
            sum += m[i];
        *mean = sum / t->rep_len;
        *partition = n;
    }
    free(p);
    free(from);
    free(to);
    free(m);
    free(prefix);
    return ok;
}

/* splitmix64: the same stream on every machine. */
static uint64_t next_random(uint64_t *s)
{
    uint64_t z = (*s += UINT64_C(0x9E3779B97F4A7C15));
    z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
    return z ^ (z >> 31);
}

void cm_te_ensemble_run(const cm_te *t, long n, uint64_t seed, cm_te_ensemble *out)
{
    enum { MAX_STEPS = 4096 };
    long *escaped_at = calloc(MAX_STEPS + 1, sizeof *escaped_at);
    out->points = n;
    out->mean = out->kappa = NAN;
    out->fit_from = out->fit_to = 0;
    if (!escaped_at)
        return;
    double sum = 0;
    for (long i = 0; i < n; i++) {
        const double u = (double)(next_random(&seed) >> 11) * 0x1.0p-53;
        const long k = cm_te_escape_number(t, t->x0 + u * t->rep_len, MAX_STEPS);
        escaped_at[k < 0 ? MAX_STEPS : k]++;
        sum += (double)(k < 0 ? MAX_STEPS : k);
    }
    out->mean = sum / (double)n;
    /* survivors after k steps, ln of them fitted by a line over the tail:
     * from where N/e remain to where 1000 do */
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    long left = n;
    int count = 0;
    for (int k = 0; k < MAX_STEPS && left >= 1000; k++) {
        left -= escaped_at[k];
        if (left > (double)n / 2.718281828459045 || left < 1000)
            continue;
        if (count == 0)
            out->fit_from = k + 1;
        out->fit_to = k + 1;
        const double x = k + 1, y = log((double)left);
        sx += x, sy += y, sxx += x * x, sxy += x * y;
        count++;
    }
    if (count >= 3)
        out->kappa = -(count * sxy - sx * sy) / (count * sxx - sx * sx);
    free(escaped_at);
}
