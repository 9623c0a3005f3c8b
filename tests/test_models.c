#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "models/delay_domains.h"
#include "models/delay_partition.h"
#include "models/pd_strips.h"
#include "models/microchaos_pd.h"
#include "models/params.h"
#include "models/registry.h"

static cm_model make(const char *name, const char *params)
{
    cm_model m;
    char msg[256];
    const char *texts[1] = {params};
    if (cm_model_create(name, texts, params ? 1 : 0, &m, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cannot build %s: %s\n", name, msg);
        exit(1);
    }
    return m;
}

static size_t fixed(const cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *fp)
{
    size_t n = 0;
    char msg[256];
    CHECK(m->fixed_points(m, m0, m1, fp, 64, &n, msg, sizeof msg) == 0);
    return n;
}

/* Thesis Fig. 4.2: x_8* = 8.96 regular, x_9* = 10.08 virtual. */
static void fig_4_2(void)
{
    cm_model m = make("microchaos-1d", "a=3.5,b=2.8");
    cm_fixed_point fp[64];
    const size_t n = fixed(&m, 0, 9, fp);
    CHECK_INT(n, 10);
    CHECK_NEAR(fp[8].x[0], 8.96, 1e-12);
    CHECK(fp[8].regular);
    CHECK_NEAR(fp[9].x[0], 10.08, 1e-12);
    CHECK(!fp[9].regular);
    CHECK_INT(fp[9].band, 10);
    for (int k = 0; k <= 8; k++)
        CHECK(fp[k].regular); /* m_fix,max = Int(1/(1.12 - 1)) = 8 */
    cm_model_release(&m);
}

/* Fig. 4.13: five regular fixed points, x_3* virtual in band 4. */
static void fig_4_13(void)
{
    cm_model m = make("microchaos-pd", "alpha=0.8,beta=0.3,P=0.9,D=0.4");
    cm_fixed_point fp[64];
    const size_t n = fixed(&m, -5, 5, fp);
    int regular = 0;
    for (size_t i = 0; i < n; i++)
        regular += fp[i].regular;
    CHECK_INT(regular, 5);
    CHECK(fp[5 + 2].regular);
    CHECK(!fp[5 + 3].regular);
    CHECK_INT(fp[5 + 3].band, 4);
    CHECK_NEAR(fp[5 + 3].x[0], 3 / 0.64, 1e-14);
    CHECK_INT(cm_pd_m_fix_max(0.8, 0.9), 2);
    CHECK_INT(cm_pd_m_max(0.8, 0.9), 3);
    cm_model_release(&m);
}

/* The band test wins at a border collision (docs/models.md 6.4): P = 3/2 alpha^2
 * puts x_2* exactly on SW_3 ... if the arithmetic is exact; either way the
 * count must match the fixed points the model calls regular. */
static void border_collision(void)
{
    const double alphas[] = {0.5, 0.8, 0.078, 6.8511e-3};
    for (int a = 0; a < 4; a++)
        for (int k = 1; k <= 6; k++) {
            const double alpha = alphas[a], P = alpha * alpha * (k + 1) / k;
            char text[128];
            snprintf(text, sizeof text, "alpha=%.17g,P=%.17g,D=0.1", alpha, P);
            cm_model m = make("microchaos-pd", text);
            cm_fixed_point fp[64];
            const size_t n = fixed(&m, 0, 20, fp);
            int64_t largest = -1;
            for (size_t i = 0; i < n; i++)
                if (fp[i].regular)
                    largest = fp[i].level;
            CHECK_INT(cm_pd_m_fix_max(alpha, P), largest);
            CHECK(largest == k || largest == k - 1);
            cm_model_release(&m);
        }
    CHECK_INT(cm_pd_m_fix_max(0.8, 0.5), -1); /* P <= alpha^2: unbounded */
}

/* exp of the 2x2 matrix [[0, 1], [a2, -2 beta]] by a long Taylor series:
 * an evaluation independent of the closed form (4.67). */
static void expm2(double a2, double beta, double *E)
{
    const double M[4] = {0, 1, a2, -2 * beta};
    double term[4] = {1, 0, 0, 1};
    E[0] = 1, E[1] = 0, E[2] = 0, E[3] = 1;
    for (int k = 1; k < 60; k++) {
        const double t[4] = {(term[0] * M[0] + term[1] * M[2]) / k,
                             (term[0] * M[1] + term[1] * M[3]) / k,
                             (term[2] * M[0] + term[3] * M[2]) / k,
                             (term[2] * M[1] + term[3] * M[3]) / k};
        memcpy(term, t, sizeof t);
        for (int i = 0; i < 4; i++)
            E[i] += term[i];
    }
}

static void pd_coefficients(void)
{
    const double cases[][4] = {{0.078, 0, 0.007, 0.02}, {0.8, 0.3, 0.9, 0.4}, {0.5, -0.2, 1, 2}};
    for (int c = 0; c < 3; c++) {
        cm_pd_coef k;
        cm_pd_coefficients(cases[c][0], cases[c][1], cases[c][2], cases[c][3], &k);
        double E[4];
        const double a2 = cases[c][0] * cases[c][0];
        expm2(a2, cases[c][1], E);
        for (int i = 0; i < 4; i++)
            CHECK_NEAR(k.A[i], E[i], 1e-12);
        /* b = (I - A) [1/alpha^2, 0] */
        CHECK_NEAR(k.b[0], (1 - k.A[0]) / a2, 1e-12);
        CHECK_NEAR(k.b[1], -k.A[2] / a2, 1e-12);
        /* e_u, e_s are eigenvectors with eigenvalues exp(+-gamma - beta) */
        CHECK_NEAR(k.A[0] + k.A[1] * k.e_u[1], k.lambda_u, 1e-12);
        CHECK_NEAR(k.A[2] + k.A[3] * k.e_u[1], k.lambda_u * k.e_u[1], 1e-12);
        CHECK_NEAR(k.A[2] + k.A[3] * k.e_s[1], k.lambda_s * k.e_s[1], 1e-12);
        /* (4.62) written out */
        const double g = k.gamma, s = sinh(g), ch = cosh(g), e = exp(k.beta), P = k.P, D = k.D;
        CHECK_NEAR(k.S[0], ((a2 - P) * (k.beta * s + g * ch) + P * e * g) / a2 / (e * g), 1e-12);
        CHECK_NEAR(k.S[1], (a2 * s - (k.beta * s + g * ch - e * g) * D) / a2 / (e * g), 1e-12);
        CHECK_NEAR(k.S[2], (a2 - P) * s / (e * g), 1e-12);
        CHECK_NEAR(k.S[3], (g * ch - (k.beta + D) * s) / (e * g), 1e-12);
    }
}

/* Stability domain (C.43)-(C.47) against the eigenvalues of S. */
static void stability_domain(void)
{
    const double alpha = 0.8, beta = 0.3;
    int agree = 0, total = 0, stable = 0;
    for (double P = -0.5; P <= 3.0; P += 0.0371)
        for (double D = -1.0; D <= 3.0; D += 0.0433) {
            cm_pd_coef k;
            cm_pd_stability st;
            cm_pd_coefficients(alpha, beta, P, D, &k);
            cm_pd_stability_at(alpha, beta, P, D, &st);
            const double tr = k.S[0] + k.S[3], det = k.S[0] * k.S[3] - k.S[1] * k.S[2];
            CHECK_NEAR(st.p, -tr, 1e-11);
            CHECK_NEAR(st.q, det, 1e-11);
            const double disc = tr * tr / 4 - det;
            const double radius = disc >= 0 ? fmax(fabs(tr / 2 + sqrt(disc)), fabs(tr / 2 - sqrt(disc)))
                                            : sqrt(det);
            if (fabs(radius - 1) < 1e-9)
                continue; /* on the boundary */
            total++;
            agree += (radius < 1) == (st.stable != 0);
            stable += radius < 1;
            if ((radius < 1) && st.stable)
                CHECK(P > alpha * alpha && st.D_b1 < D && D < st.D_b0);
        }
    CHECK_INT(agree, total);
    CHECK(stable > 50);
    const double Pmax = cm_pd_P_max(alpha, beta);
    cm_pd_stability at;
    cm_pd_stability_at(alpha, beta, Pmax, 0, &at);
    CHECK_NEAR(at.D_b0, at.D_b1, 1e-12);
    CHECK_NEAR(at.D_b0, cm_pd_D_at_P_max(alpha, beta), 1e-12);
    /* the eigen-structure curves (C.52)-(C.56) against S itself: trace 0 on
     * D_1, det 0 on D_0, a double eigenvalue on D_c+-, and at P_quick both
     * eigenvalues 0 where D_0 and D_1 meet */
    for (double P = alpha * alpha * 1.01; P < Pmax; P += 0.05) {
        cm_pd_eigen_curves ec;
        cm_pd_eigen_curves_at(alpha, beta, P, &ec);
        const double Ds[4] = {ec.D_1, ec.D_0, ec.D_c_minus, ec.D_c_plus};
        for (int k = 0; k < 4; k++) {
            cm_pd_coef c;
            cm_pd_coefficients(alpha, beta, P, Ds[k], &c);
            const double tr = c.S[0] + c.S[3], det = c.S[0] * c.S[3] - c.S[1] * c.S[2];
            const double want[4] = {tr, det, tr * tr - 4 * det, tr * tr - 4 * det};
            CHECK(fabs(want[k]) < 1e-10);
        }
        CHECK(ec.D_c_minus <= ec.D_c_plus);
    }
    cm_pd_eigen_curves below;
    cm_pd_eigen_curves_at(alpha, beta, alpha * alpha * 0.9, &below);
    CHECK(isnan(below.D_c_plus)); /* complex below P = alpha^2 */
    const double Pq = cm_pd_P_quick(alpha, beta);
    cm_pd_eigen_curves q;
    cm_pd_eigen_curves_at(alpha, beta, Pq, &q);
    CHECK_NEAR(q.D_0, q.D_1, 1e-12);
    cm_pd_coef cq;
    cm_pd_coefficients(alpha, beta, Pq, q.D_0, &cq);
    CHECK(fabs(cq.S[0] + cq.S[3]) < 1e-12 && fabs(cq.S[0] * cq.S[3] - cq.S[1] * cq.S[2]) < 1e-12);
}

/* ---- horseshoes (thesis 4.5.3) ----------------------------------------- */

/* Whether y - x is parallel to the direction (1, slope), to tol. */
static bool along(const double x[2], const double y[2], double slope, double tol)
{
    return fabs((y[1] - x[1]) - slope * (y[0] - x[0])) < tol;
}

static void horseshoes(void)
{
    /* the corners where the thesis' lines meet, checked on the lines
     * themselves: W^U along e_u = (1, gamma - beta), W^S along e_s = (1,
     * -gamma - beta) through the fixed points, SW_m: P x + D x' = m */
    const double alpha = 0.8, beta = 0.3, P = 0.7, D = 0.6;
    const double g = sqrt(alpha * alpha + beta * beta), u = g - beta, st = -g - beta;
    for (int m = 1; m <= 8; m++) {
        cm_pd_horseshoe h;
        cm_pd_horseshoe_at(alpha, beta, P, D, m, &h);
        CHECK(along(h.x_r, h.RULS, u, 1e-12) && along(h.x_l, h.RULS, st, 1e-12));
        CHECK(along(h.x_l, h.LURS, u, 1e-12) && along(h.x_r, h.LURS, st, 1e-12));
        CHECK(along(h.x_r, h.RUSW, u, 1e-12) && fabs(P * h.RUSW[0] + D * h.RUSW[1] - m) < 1e-12);
        CHECK(along(h.x_l, h.LUSW, u, 1e-12) && fabs(P * h.LUSW[0] + D * h.LUSW[1] - m) < 1e-12);
        /* and the thesis' own printed forms of P^RUSW and P^LUSW */
        const double a2 = alpha * alpha, den = -beta * D + D * g + P;
        CHECK(fabs(h.RUSW[0] - (a2 + D * (-beta + g)) * m / (a2 * den)) < 1e-12);
        CHECK(fabs(h.RUSW[1] + (beta - g) * m * (a2 - P) / (a2 * den)) < 1e-12);
        const double den2 = a2 * (beta * D - D * g - P);
        CHECK(fabs(h.LUSW[0] - (D * (beta - g) * (m - 1) - a2 * m) / den2) < 1e-12);
        CHECK(fabs(h.LUSW[1] - (beta - g) * (a2 * m + P - m * P) / den2) < 1e-12);
    }
    /* Fig. 4.16: repellers at SW_4 and SW_7, attractors at SW_5 and SW_6 */
    for (int m = 4; m <= 7; m++) {
        cm_pd_horseshoe h;
        cm_pd_horseshoe_at(alpha, beta, P, D, m, &h);
        CHECK(h.stretches == (m == 4 || m == 7));
        CHECK(!h.full_shift);
    }
    /* Fig. 4.18 at SW_3 (alpha = 0.77, beta = 0.02, D = 0.83): a full binary
     * shift at P = 0.71, with 2^n points of period n (entropy log 2); at
     * 0.655 and 0.67 not, and fewer */
    const double Ps[3] = {0.655, 0.67, 0.71};
    for (int k = 0; k < 3; k++) {
        cm_pd_horseshoe h;
        cm_pd_horseshoe_at(0.77, 0.02, Ps[k], 0.83, 3, &h);
        CHECK(h.full_shift == (k == 2));
        for (int n = 1; n <= 12; n++) {
            const uint64_t N = cm_pd_horseshoe_periodic(0.77, 0.02, Ps[k], 0.83, 3, n);
            if (k == 2)
                CHECK(N == UINT64_C(1) << n);
            else if (n >= 4)
                CHECK(N < UINT64_C(1) << n);
        }
    }
}

/* ---- the delay map's partition (thesis 4.4.2, App. C.3) ---------------- */

static void delay_partition(void)
{
    /* Fig. 4.11 (a = 1.3, b = 0.66): nine regions and the matrix (4.53),
     * irreducible and primitive with index N = 65 <= r^2 - r = 72 */
    static const char *const thesis[9] = {"010000000", "001000000", "000100000",
                                          "000011000", "000001000", "000000100",
                                          "000000010", "000000001", "100000000"};
    cm_delay_partition p;
    char why[200];
    CHECK(cm_delay_partition_01(1.3, 0.66, &p, why, sizeof why));
    CHECK_INT(p.r, 9);
    for (int i = 0; i < 9 && p.r == 9; i++)
        for (int j = 0; j < 9; j++)
            CHECK_INT(p.P[i][j], thesis[i][j] - '0');
    CHECK(p.irreducible);
    CHECK_INT(p.primitive_index, 65);
    CHECK(fabs(p.x_l - 0.172) < 1e-12 && fabs(p.x_r - 1.69) < 1e-12);
    /* the regions tile the two branches; each transition P_ij = 1 checked on
     * the map itself: 1000 points of I_j all have a pre-image in I_i */
    for (int i = 0; i < p.r; i++)
        for (int j = 0; j < p.r; j++) {
            if (!p.P[i][j])
                continue;
            for (int k = 0; k <= 1000; k++) {
                const double s = p.lo[j] + (p.hi[j] - p.lo[j]) * k / 1000.0;
                /* f takes (t, a t - b branch_i) to branch Int(t) at a t - b branch_i */
                const double t = (s + 0.66 * p.branch[i]) / 1.3;
                CHECK(t >= p.lo[i] - 1e-12 && t <= p.hi[i] + 1e-12);
                CHECK((t >= 1) == (p.branch[j] == 1) || fabs(t - 1) < 1e-12);
            }
        }
    /* App. C.3.2: primitive partitions for c_m^u = 0.5953 <= b <= c_s^l =
     * 0.6766 at a = 1.3; below, this construction is not irreducible */
    for (double b = 0.6; b <= 0.675; b += 0.0125) {
        CHECK(cm_delay_partition_01(1.3, b, &p, why, sizeof why));
        CHECK(p.irreducible && p.primitive_index > 0 &&
              p.primitive_index <= p.r * p.r - p.r);
    }
    CHECK(cm_delay_partition_01(1.3, 0.58, &p, why, sizeof why) && !p.irreducible);
    CHECK(!cm_delay_partition_01(1.5, 0.6, &p, why, sizeof why)); /* Fig. 4.9: m_min = 2 */
}

/* ---- orbits against independent evaluations of the formulas ---------- */

static double Int(double z) { return trunc(z); }

static double urand(unsigned *seed, double lo, double hi)
{
    *seed = *seed * 1103515245u + 12345u;
    return lo + (hi - lo) * ((*seed >> 8) & 0xffffff) / 16777216.0;
}

static void compare_step(const cm_model *m, const double *x, const double *expect, const char *what)
{
    double y[CM_MAX_DIM];
    CHECK_INT(m->step(m, x, y), 0);
    for (int d = 0; d < m->dim; d++)
        if (!(fabs(y[d] - expect[d]) <= 1e-12 * fmax(1.0, fabs(expect[d])))) {
            fprintf(stderr, "%s: step(%.17g, ...)[%d] = %.17g, expected %.17g\n", what, x[0], d,
                    y[d], expect[d]);
            check_failures++;
        }
}

static void orbits(void)
{
    unsigned seed = 7;
    cm_model m1 = make("microchaos-1d", "a=3.5,b=2.8");
    cm_model mf = make("microchaos-1d-friction", "a=1.5,b=1.2,c=0.1333");
    cm_model md = make("microchaos-delay", "a=1.3,b=0.66");
    cm_model mp = make("microchaos-pd", "alpha=0.8,beta=0.3,P=0.9,D=0.4");
    cm_model mt = make("microchaos-pd-twofold", "alpha=0.8,beta=0.3,P=0.9,D=0.4,rho=0.7");
    double E[4];
    expm2(0.64, 0.3, E);
    const double b0 = (1 - E[0]) / 0.64, b1 = -E[2] / 0.64;
    for (int i = 0; i < 2000; i++) {
        double x[2] = {urand(&seed, -12, 12), urand(&seed, -12, 12)}, e[2] = {0, 0};
        e[0] = 3.5 * x[0] - 2.8 * Int(x[0]);
        compare_step(&m1, x, e, "microchaos-1d");
        const double a = 1.5, c = 0.1333;
        e[0] = x[0] > c / a ? a * x[0] - 1.2 * Int(x[0]) - c
                            : (x[0] < -c / a ? a * x[0] - 1.2 * Int(x[0]) + c : 0.0);
        compare_step(&mf, x, e, "microchaos-1d-friction");
        e[0] = x[1];
        e[1] = 1.3 * x[1] - 0.66 * Int(x[0]);
        compare_step(&md, x, e, "microchaos-delay");
        double mj = Int(0.9 * x[0] + 0.4 * x[1]);
        e[0] = E[0] * x[0] + E[1] * x[1] + b0 * mj;
        e[1] = E[2] * x[0] + E[3] * x[1] + b1 * mj;
        compare_step(&mp, x, e, "microchaos-pd");
        mj = Int(0.7 * (0.9 * Int(x[0] / 0.7) + 0.4 * Int(x[1] / 0.7)));
        e[0] = E[0] * x[0] + E[1] * x[1] + b0 * mj;
        e[1] = E[2] * x[0] + E[3] * x[1] + b1 * mj;
        compare_step(&mt, x, e, "microchaos-pd-twofold");
    }
    /* The dead zone maps to 0 and huge or NaN arguments have no image. */
    double x = 0.05, y;
    CHECK_INT(mf.step(&mf, &x, &y), 0);
    CHECK(y == 0.0);
    x = NAN;
    CHECK_INT(m1.step(&m1, &x, &y), CM_STEP_NO_IMAGE);
    x = 1e300;
    CHECK_INT(m1.step(&m1, &x, &y), CM_STEP_NO_IMAGE);
    cm_model_release(&m1);
    cm_model_release(&mf);
    cm_model_release(&md);
    cm_model_release(&mp);
    cm_model_release(&mt);
}

/* microchaos-general reproduces the specific maps it generalises. */
static void general_equals_specific(void)
{
    cm_pd_coef k;
    /* Gains with no simple ratio to rho, so that rho (P i + D j) never lands on
     * an integer, where the two evaluation orders could round differently. */
    cm_pd_coefficients(0.8, 0.3, 0.9137, 0.4211, &k);
    char pd_text[512];
    snprintf(pd_text, sizeof pd_text, "n=2,A=%.17g:%.17g:%.17g:%.17g,B=%.17g:%.17g,K=0.9137:0.4211",
             k.A[0], k.A[1], k.A[2], k.A[3], k.b[0], k.b[1]);
    const struct {
        const char *name, *params, *general;
    } pairs[] = {
        {"microchaos-1d", "a=3.5,b=2.8", "A=3.5,B=-2.8,K=1"},
        {"microchaos-delay", "a=1.3,b=0.66", "d=1,A=1.3,B=-0.66,K=0:1"},
        {"microchaos-pd", "alpha=0.8,beta=0.3,P=0.9137,D=0.4211", pd_text},
        {"microchaos-pd-twofold", "alpha=0.8,beta=0.3,P=0.9137,D=0.4211,rho=0.7",
         "mode=twofold,rO=1,rI=0.7"},
    };
    unsigned seed = 11;
    for (int p = 0; p < 4; p++) {
        cm_model s = make(pairs[p].name, pairs[p].params);
        const char *texts[2] = {pd_text, pairs[p].general};
        cm_model g;
        char msg[256];
        CHECK(cm_model_create("microchaos-general", texts, p == 3 ? 2 : 1, &g, msg, sizeof msg) ==
              CM_OK);
        if (p < 3) {
            cm_model_release(&g);
            const char *one[1] = {pairs[p].general};
            CHECK(cm_model_create("microchaos-general", one, 1, &g, msg, sizeof msg) == CM_OK);
        }
        CHECK_INT(g.dim, s.dim);
        for (int i = 0; i < 1000; i++) {
            double x[2] = {urand(&seed, -20, 20), urand(&seed, -20, 20)}, ys[2], yg[2];
            CHECK_INT(s.step(&s, x, ys), g.step(&g, x, yg));
            for (int d = 0; d < s.dim; d++)
                CHECK_NEAR(yg[d], ys[d], 1e-13);
        }
        cm_fixed_point fs[64], fg[64];
        const size_t ns = fixed(&s, -4, 4, fs), ng = fixed(&g, -4, 4, fg);
        CHECK_INT(ns, ng);
        for (size_t i = 0; i < ns && i < ng; i++) {
            CHECK_INT(fs[i].regular, fg[i].regular);
            CHECK_NEAR(fg[i].x[0], fs[i].x[0], 1e-9);
        }
        cm_model_release(&s);
        cm_model_release(&g);
    }
}

/* The 1-D friction map's overlays at Fig. 4.5's a = 1.5, b = 1.3, |I0| =
 * 0.25 (c = 0.15), on the diagonal of the graph plane: I0 = [a - b - c, x0*]
 * and I_rep = [x0*, a - c] with their mirror images, and the fixed points.
 * Checked on the map: I_rep goes into I0 and I_rep, and I0 to rest at 0
 * without coming back above x0*. */
static void friction_1d_overlays(void)
{
    cm_model mf = make("microchaos-1d-friction", "a=1.5,b=1.3,c=0.15");
    cm_overlay items[64];
    cm_overlay_list ov = {items, 64, 0, false};
    mf.overlays(&mf, (const double[2]){-2, -2}, (const double[2]){2, 2}, &ov);
    CHECK(!ov.truncated);
    const double x0 = 0.15 / 0.5, lo = 1.5 - 1.3 - 0.15, hi = 1.5 - 0.15;
    int escape = 0, repeller = 0, points = 0;
    for (size_t i = 0; i < ov.count; i++) {
        const cm_overlay *o = &items[i];
        if (o->kind == CM_OVERLAY_FIXED_REGULAR || o->kind == CM_OVERLAY_FIXED_VIRTUAL) {
            points++;
            CHECK(o->a[0] == o->a[1]);
            continue;
        }
        CHECK(o->a[0] == o->a[1] && o->b[0] == o->b[1]); /* on the diagonal */
        const double s = o->a[0] + o->b[0] > 0 ? 1 : -1, a = s * fmin(s * o->a[0], s * o->b[0]),
                     b = s * fmax(s * o->a[0], s * o->b[0]); /* a: the end nearer 0 */
        if (o->kind == CM_OVERLAY_ESCAPE) {
            escape++;
            CHECK_NEAR(a, s * lo, 1e-15);
            CHECK_NEAR(b, s * x0, 1e-15);
        } else {
            CHECK_INT(o->kind, CM_OVERLAY_REPELLER);
            repeller++;
            CHECK_NEAR(a, s * x0, 1e-15);
            CHECK_NEAR(b, s * hi, 1e-15);
        }
        for (int k = 1; k < 100; k++) {
            double x = a + (b - a) * k / 100.0, y;
            CHECK_INT(mf.step(&mf, &x, &y), CM_STEP_OK);
            if (o->kind == CM_OVERLAY_REPELLER) {
                CHECK(s * y >= lo - 1e-12 && s * y <= hi + 1e-12);
                continue;
            }
            for (int t = 0; t < 100 && x != 0; t++) {
                CHECK(s * x < x0);
                mf.step(&mf, &x, &y);
                x = y;
            }
            CHECK(x == 0);
        }
    }
    CHECK_INT(escape, 2);
    CHECK_INT(repeller, 2);
    CHECK(points >= 3); /* the origin and +-x0* */
    cm_model_release(&mf);
}

static void friction_and_delay_fixed_points(void)
{
    cm_model mf = make("microchaos-1d-friction", NULL); /* Fig. 4.4 defaults */
    const double a = 1.5, b = 1.2, c = 0.13333333333333333;
    /* (4.27): |I0| = a c/(a-1) - (a-b) = 0.1 */
    CHECK_NEAR(a * cm_params_get(&mf.values, "c") / (a - 1) - (a - b), 0.1, 1e-12);
    cm_fixed_point fp[64];
    const size_t n = fixed(&mf, 0, 1, fp);
    CHECK_INT(n, 4); /* origin, -c/(a-1), +c/(a-1), (b + c)/(a-1) */
    CHECK(fp[0].regular && fp[0].x[0] == 0.0);
    CHECK_NEAR(fp[2].x[0], c / (a - 1), 1e-14);
    CHECK(fp[2].regular);
    CHECK(fp[1].regular); /* -c/(a-1): the mirror image, also in band 0 */
    CHECK_NEAR(fp[3].x[0], (b + c) / (a - 1), 1e-14); /* 2.67: band 2, virtual */
    CHECK(!fp[3].regular);
    cm_model_release(&mf);
    friction_1d_overlays();
    cm_model md = make("microchaos-delay", "a=1.5,b=0.6");
    const size_t nd = fixed(&md, 0, 6, fp);
    for (size_t i = 0; i < nd; i++) {
        CHECK_NEAR(fp[i].x[0], 1.2 * (double)fp[i].level, 1e-14);
        CHECK_INT(fp[i].regular, fp[i].level <= 4);
    }
    /* its overlays on [0, 6]^2 (Fig. 4.9): the band borders x = 1..6, the
     * lines U_0..U_6 where they cross the view, each on x_j = a x - b m,
     * and the fixed points y_0*..y_5* (y_5* = (6, 6) lies on the corner) */
    cm_overlay items[64];
    cm_overlay_list ov = {items, 64, 0, false};
    md.overlays(&md, (const double[2]){0, 0}, (const double[2]){6, 6}, &ov);
    CHECK(!ov.truncated);
    int borders = 0, lines = 0, points = 0;
    for (size_t i = 0; i < ov.count; i++) {
        const cm_overlay *o = &items[i];
        if (o->kind == CM_OVERLAY_SWITCHING_LINE) {
            borders++;
            CHECK(o->a[0] == o->b[0] && o->a[0] == round(o->a[0]));
        } else if (o->kind == CM_OVERLAY_UNSTABLE_MANIFOLD) {
            lines++;
            const double m = (1.5 * o->a[0] - o->a[1]) / 0.6; /* x_j = a x - b m at both ends */
            CHECK(fabs(m - round(m)) < 1e-12 && fabs(1.5 * o->b[0] - 0.6 * round(m) - o->b[1]) < 1e-12);
        } else {
            points++;
            CHECK(o->a[0] == o->a[1]);
            CHECK_INT(o->kind == CM_OVERLAY_FIXED_REGULAR, round(o->a[0] / 1.2) <= 4);
        }
    }
    CHECK_INT(borders, 6);
    CHECK(lines >= 6);
    CHECK_INT(points, 6);
    cm_model_release(&md);
    /* twofold quantisation (Figs. 4.33-4.36): each stair of the switching
     * lines is an edge of the rho x rho input tiles, and the control level
     * (read off one step of the map) differs on its two sides */
    const double rho = 0.7;
    cm_model mt = make("microchaos-pd-twofold", "alpha=0.8,beta=0.3,P=0.9,D=0.4,rho=0.7");
    CHECK(strcmp(cm_model_coord_name(&mt, 1), "v") == 0);
    cm_pd_coef k;
    cm_pd_coefficients(0.8, 0.3, 0.9, 0.4, &k);
    cm_overlay stairs[4096];
    cm_overlay_list st = {stairs, 4096, 0, false};
    mt.overlays(&mt, (const double[2]){-6, -3}, (const double[2]){6, 3}, &st);
    CHECK(!st.truncated);
    int edges = 0;
    for (size_t i = 0; i < st.count; i++) {
        const cm_overlay *o = &stairs[i];
        if (o->kind != CM_OVERLAY_SWITCHING_LINE)
            continue;
        edges++;
        const bool vertical = o->a[0] == o->b[0];
        CHECK(vertical || o->a[1] == o->b[1]);
        CHECK(fabs(fabs(o->b[0] - o->a[0]) + fabs(o->b[1] - o->a[1]) - rho) < 1e-12);
        const double mid[2] = {0.5 * (o->a[0] + o->b[0]), 0.5 * (o->a[1] + o->b[1])};
        double level[2];
        for (int side = 0; side < 2; side++) {
            const double e = side ? 1e-6 : -1e-6;
            const double x[2] = {mid[0] + (vertical ? e : 0), mid[1] + (vertical ? 0 : e)};
            double y[2];
            CHECK_INT(mt.step(&mt, x, y), 0);
            level[side] = (y[1] - k.A[2] * x[0] - k.A[3] * x[1]) / k.b[1];
        }
        CHECK(fabs(level[0] - level[1]) > 0.5);
    }
    CHECK(edges > 20);
    cm_model_release(&mt);
}

/* The control level of twofold quantisation at x, read off one step. */
static double twofold_level(const cm_model *m, const cm_pd_coef *k, double x, double v)
{
    const double s[2] = {x, v};
    double y[2];
    CHECK_INT(m->step(m, s, y), 0);
    return round((y[1] - k->A[2] * x - k->A[3] * v) / k->b[1]);
}

typedef struct slc_count {
    int first, higher; /* collision points of order 1 and >= 2 */
    int ties;          /* vertical (horizontal) edges where the level before output
                          rounding is an integer in exact arithmetic */
    int jumps;         /* other such edges across which the level jumps by n */
} slc_count;

/* Switching line collisions of Figs. 4.34-4.35 (P = 2/5, D = 2/9) over
 * tiles 2..60 in x and x' (off the double deadzone at 0), each checked on
 * the map: the four tiles' levels, one diagonal below and above the other. */
static slc_count twofold_slc(double rho, int n_jump, bool vertical)
{
    char text[160];
    snprintf(text, sizeof text, "alpha=0.5,beta=0.1,P=0.4,D=%.17g,rho=%.17g", 2.0 / 9, rho);
    cm_model m = make("microchaos-pd-twofold", text);
    cm_pd_coef k;
    cm_pd_coefficients(0.5, 0.1, 0.4, 2.0 / 9, &k);
    static cm_overlay items[1 << 15];
    cm_overlay_list ov = {items, 1 << 15, 0, false};
    const double lo[2] = {2 * rho + 1e-9 * rho, 2 * rho + 1e-9 * rho}, hi[2] = {60 * rho, 60 * rho};
    m.overlays(&m, lo, hi, &ov);
    CHECK(!ov.truncated);
    slc_count n = {0, 0, 0, 0};
    int switching = 0, differing = 0; /* edges inside: overlays, and by the map */
    for (size_t i = 0; i < ov.count; i++) {
        const cm_overlay *o = &items[i];
        if (o->kind == CM_OVERLAY_SWITCHING_LINE) {
            switching += o->a[0] > lo[0] && o->b[0] < hi[0] && o->a[1] > lo[1] && o->b[1] < hi[1];
            continue;
        }
        if (o->kind != CM_OVERLAY_COLLISION && o->kind != CM_OVERLAY_COLLISION_HIGHER)
            continue;
        const double h = rho / 2, x = o->a[0], v = o->a[1];
        const double a = twofold_level(&m, &k, x - h, v - h), b = twofold_level(&m, &k, x + h, v - h),
                     c = twofold_level(&m, &k, x - h, v + h), d = twofold_level(&m, &k, x + h, v + h);
        /* with P, D > 0 the levels grow to the upper right: a, d around b, c */
        CHECK(a < fmin(b, c) && d > fmax(b, c));
        const int order = (int)fabs(b - c) + 1;
        CHECK_INT(o->kind == CM_OVERLAY_COLLISION, order == 1);
        if (order == 1)
            n.first++;
        else
            n.higher++;
    }
    /* tiles i, k: [i rho, (i + 1) rho) x [k rho, (k + 1) rho) */
    for (int i = 3; i < 60; i++)
        for (int j = 3; j < 59; j++)
            for (int e = 0; e < 2; e++) { /* e = 0: the edge x = i rho; 1: x' = i rho */
                const int ti = e ? j : i, tk = e ? i : j; /* the tile above or right */
                const double upper = twofold_level(&m, &k, (ti + 0.5) * rho, (tk + 0.5) * rho),
                             lower = twofold_level(&m, &k, (ti - !e + 0.5) * rho,
                                                   (tk - e + 0.5) * rho);
                differing += upper != lower;
                if (e != vertical) {
                    const double z = rho * (0.4 * (ti - !e) + 2.0 / 9 * (tk - e));
                    const bool tie = fabs(z - round(z)) < 1e-9;
                    n.ties += tie;
                    n.jumps += !tie && upper - lower == n_jump;
                }
            }
    CHECK_INT(switching, differing); /* the stairs are where the map's level changes */
    cm_model_release(&m);
    return n;
}

/* Thesis (4.87)-(4.92) at P = 2/5, D = 2/9: first-order collisions exist
 * only for 1/(P + D) < rho < 1/(P - D) (the lowest and highest ratios), and
 * from there higher orders take their place; at rho = n/P the level jumps
 * by exactly n across every vertical tile edge (so each switching line
 * meets its n-th neighbour at every x = i rho), at n/D across every
 * horizontal one. Edges where the level before output rounding is an
 * integer in exact arithmetic are ties that floating point may round
 * either way; they are left out. */
static void twofold_collision_ratios(void)
{
    const double P = 0.4, D = 2.0 / 9;
    const int edges = 57 * 56; /* vertical (or horizontal) tile edges counted */
    CHECK_INT(twofold_slc(0.99 / (P + D), 1, true).first, 0);
    CHECK(twofold_slc(1.01 / (P + D), 1, true).first > 0);
    CHECK(twofold_slc(0.99 / (P - D), 1, true).first > 0);
    const slc_count above = twofold_slc(1.01 / (P - D), 1, true);
    CHECK(above.first == 0 && above.higher > 0);
    const slc_count left = twofold_slc(1.0, 1, true), right = twofold_slc(1.65, 1, true);
    CHECK(left.first + left.higher == 0 && right.first > 0); /* Fig. 4.34 */
    CHECK(twofold_slc(2 / P, 2, true).higher > 0);           /* Fig. 4.35 (right) */
    for (int n = 1; n <= 2; n++)
        for (int vertical = 1; vertical >= 0; vertical--) {
            const double rho = n / (vertical ? P : D);
            const slc_count at = twofold_slc(rho, n, vertical);
            CHECK(at.ties < edges / 4);
            CHECK_INT(at.jumps + at.ties, edges);
            const slc_count below = twofold_slc(0.97 * rho, n, vertical);
            CHECK(below.jumps + below.ties < edges); /* some edges jump by n - 1 */
        }
}

static void parameter_errors(void)
{
    const struct {
        const char *model, *text, *needle;
    } bad[] = {
        {"microchaos-pd", "gamma=1", "unknown parameter"},
        {"microchaos-pd", "alpha=0", "outside"},
        {"microchaos-pd", "P=abc", "not a finite number"},
        {"microchaos-pd", "P=1:2", "at most 1 value"},
        {"microchaos-pd", "P", "name=value"},
        {"microchaos-general", "n=2,d=3", "exceeds"},
        {"microchaos-general", "n=2,A=1:2:3", "needs 4 values"},
        {"microchaos-general", "mode=fancy", "not one of"},
        {"no-such-model", "", "unknown model"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        cm_model m;
        char msg[256] = "";
        const char *texts[1] = {bad[i].text};
        CHECK(cm_model_create(bad[i].model, texts, 1, &m, msg, sizeof msg) != CM_OK);
        if (!strstr(msg, bad[i].needle)) {
            fprintf(stderr, "message for %s '%s' was '%s'\n", bad[i].model, bad[i].text, msg);
            check_failures++;
        }
    }
}

/* Fig. 4.18: the second pre-images and third images of L and R at SW_3
 * (alpha = 0.77, beta = 0.02, D = 0.83). At P = 0.71, a full shift, every
 * piece crosses Q_3: 4 third images and 4 second pre-images of each; at
 * P = 0.655 (two escape conditions fail) fewer. Each pre-image piece is
 * checked on the map: its centre stays in Q_3 and lands in the trapezoid. */
static void pd_strips(void)
{
    cm_polygon pc[64];
    for (int side = 0; side < 2; side++) {
        CHECK_INT(cm_pd_strip_images(0.77, 0.02, 0.71, 0.83, 3, side, 3, pc, 64), 4);
        const int n = cm_pd_strip_preimages(0.77, 0.02, 0.71, 0.83, 3, side, 2, pc, 64);
        CHECK_INT(n, 4);
        cm_pd_horseshoe h;
        cm_pd_horseshoe_at(0.77, 0.02, 0.71, 0.83, 3, &h);
        cm_pd_coef k;
        cm_pd_coefficients(0.77, 0.02, 0.71, 0.83, &k);
        for (int i = 0; i < n; i++) {
            double x[2] = {0, 0};
            for (int c = 0; c < pc[i].n; c++)
                x[0] += pc[i].p[c][0] / pc[i].n, x[1] += pc[i].p[c][1] / pc[i].n;
            for (int step = 0; step < 2; step++) { /* the band left or right of SW_3 */
                const double q = 0.71 * x[0] + 0.83 * x[1] < 3 ? 2 : 3;
                const double y0 = k.A[0] * x[0] + k.A[1] * x[1] + k.b[0] * q;
                x[1] = k.A[2] * x[0] + k.A[3] * x[1] + k.b[1] * q, x[0] = y0;
            }
            CHECK((0.71 * x[0] + 0.83 * x[1] >= 3) == (side == 1));
        }
    }
    int fewer = 0;
    for (int side = 0; side < 2; side++)
        fewer += cm_pd_strip_preimages(0.77, 0.02, 0.655, 0.83, 3, side, 2, pc, 64) < 4;
    CHECK(fewer > 0);
    CHECK_INT(cm_pd_strip_images(0.77, 0.02, 0.71, 0.83, 3, 0, 7, pc, 64), -1);
}

/* The parameter domains of App. C.3 (Figs. 4.10, C.3) against the thesis'
 * numbers and against orbits: inside '01' an orbit lands on U_0 and U_1
 * only, inside '012' on U_0..U_2; inside the first primitive-partition
 * domain the partition of Fig. 4.11 is irreducible and primitive. */
static void delay_domains(void)
{
    cm_delay_curves c;
    cm_delay_curves_at(1.3, &c);
    CHECK(fabs(c.c_mu - 0.5953) < 5e-5 && fabs(c.c_sl - 0.6766) < 5e-5);
    cm_delay_curves_at(1.55, &c);
    CHECK_NEAR(c.g_sup0, 0.6975, 1e-12);
    cm_delay_curves_at(1.1, &c);
    CHECK(fabs(c.d1 - 0.231) < 5e-4);
    int n01 = 0, n012 = 0, nprim = 0;
    unsigned seed = 7;
    for (int k = 0; k < 4000; k++) {
        const double a = urand(&seed, 1, 1.5), b = urand(&seed, 0, 1);
        cm_delay_domains d;
        cm_delay_domains_at(a, b, &d);
        CHECK(d.stable == (b > a - 1 && b < 1));
        if (d.d01 || d.d012) {
            const uint32_t bands = cm_delay_bands_visited(a, b, 0.37, 0.61, 2000, 20000);
            CHECK_INT(bands, d.d01 ? 3 : 7);
            n01 += d.d01, n012 += d.d012;
        }
        CHECK(!(d.d01 && d.d012));
        cm_delay_partition p;
        char why[200];
        if (d.mu_sl) {
            CHECK(cm_delay_partition_01(a, b, &p, why, sizeof why) && p.primitive_index > 0);
            nprim++;
        }
    }
    CHECK(n01 > 100 && n012 > 20 && nprim > 20);
    /* Fig. 4.9 (a = 1.5, b = 0.6): U_1..U_4, in neither domain */
    CHECK_INT(cm_delay_bands_visited(1.5, 0.6, 0.37, 0.61, 2000, 20000), 0x1e);
}

int main(void)
{
    fig_4_2();
    fig_4_13();
    border_collision();
    pd_coefficients();
    stability_domain();
    horseshoes();
    delay_partition();
    delay_domains();
    pd_strips();
    orbits();
    general_equals_specific();
    friction_and_delay_fixed_points();
    parameter_errors();
    twofold_collision_ratios();
    CHECK_DONE();
}
