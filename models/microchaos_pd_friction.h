/* models/microchaos_pd_friction.h - the hybrid micro-chaos map: the
 * PD-controlled inverted pendulum (4.65) with Coulomb friction (thesis
 * 4.7.1, (4.81); docs/models.md 8). The control level switches at sampling
 * instants only (map-like); friction switches whenever the velocity
 * changes sign (flow-like), and the block can stick between samples.
 * All functions are pure; alpha > 0 and mu_s >= mu >= 0 are required. */
#ifndef CM_MODELS_MICROCHAOS_PD_FRICTION_H
#define CM_MODELS_MICROCHAOS_PD_FRICTION_H

#include <stdbool.h>
#include <stdint.h>

typedef struct cm_pdf_coef {
    double alpha2, beta, gamma, P, D;
    double mu, mu_s;   /* kinetic and static friction, in control levels */
    double A[4], b[2]; /* one whole sampling interval (4.67) */
    double tanh_gamma; /* a velocity zero lies in (0, 1] iff 0 < w <= this */
} cm_pdf_coef;

void cm_pdf_coefficients(double alpha, double beta, double P, double D, double mu, double mu_s,
                         cm_pdf_coef *c);

/* What happens within one sampling interval (docs/models.md 8.3). */
enum cm_pdf_event_kind {
    CM_PDF_NONE = 0,
    CM_PDF_STUCK_WHOLE, /* at rest at the sample and held by static friction */
    CM_PDF_STICK,       /* the velocity reaches zero and static friction holds */
    CM_PDF_REVERSE      /* the velocity reaches zero and the block slides on */
};

typedef struct cm_pdf_result {
    double x, v;       /* the state at the next sampling instant */
    int64_t level;     /* m_j = Int(P x_j + D x'_j) */
    int event;         /* enum cm_pdf_event_kind: at most one per interval */
    double event_time; /* local time of a STICK or REVERSE, in (0, 1] */
    double event_x;    /* x there */
} cm_pdf_result;

/* One sampling interval from (x, v). Returns false when P x + D v has no
 * integer part (not finite or beyond 2^62): no image. */
bool cm_pdf_step(const cm_pdf_coef *c, double x, double v, cm_pdf_result *out);

/* Whether (x, v) is a sticking fixed point: v = 0 and static friction holds
 * the block against the control force, |alpha^2 x - Int(P x)| <= mu_s. */
bool cm_pdf_at_rest(const cm_pdf_coef *c, double x, double v);

/* The sticking zone of control level m on the line x' = 0: where static
 * friction holds and Int(P x) = m. Returns false if it is empty. */
bool cm_pdf_sticking_zone(const cm_pdf_coef *c, int64_t m, double *x_lo, double *x_hi);

#endif
