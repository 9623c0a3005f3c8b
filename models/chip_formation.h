/* models/chip_formation.h - the chip formation flows of the thesis'
 * Chapter 3 (docs/models.md 12): their coefficients and the constitutive
 * law (3.31) shared by the flows, for the analyses that need more than
 * the field. */
#ifndef CM_MODELS_CHIP_FORMATION_H
#define CM_MODELS_CHIP_FORMATION_H

#include "cellmap/model.h"
#include "models/dde.h"

/* The dimensionless coefficients of Palmai's model (thesis App. B.1) and,
 * for the elastic workpiece (B.2-B.3), its stiffness A, the reference
 * speed V0 and the speed ratio f. */
typedef struct cm_chip {
    double xi, zeta, eta, p, a, b, T_Phi;
    double A, V0, f;
} cm_chip;

/* The plastic strain rates F1, F2 of the layers at stress tau2 and
 * temperatures T1, T2 (> -1), (3.31). */
void cm_chip_rates(const cm_chip *c, double tau2, double T1, double T2, double *F1, double *F2);

#endif

/* ---- the built-up-edge delay model (thesis 3.1.4, 3.4; (3.19)-(3.26)) ----
 *
 * State (T0, T, gamma, tau): the temperatures of the inactive and active
 * layers, the shear strain and the shear stress, with delay dt (the time
 * the material spends crossing the layer). The cut layer's thickness
 * grows as a saw tooth h/h0 = 1 + H (Omega / 2 pi) (t mod 2 pi / Omega)
 * (3.24)-(3.25) while the built-up edge grows, and drops back when it
 * tears off. The strain rate is (3.22) with the hardening term
 * (1 + eps^n gamma^n) / (1 + eps^n) (the thesis prints eps^2 in the
 * numerator, a misprint for eps^n: docs/models.md 12.3), gamma^n taken as
 * 0 for gamma < 0 (the strain's power is undefined there; the solutions
 * keep gamma >= 0 after the start-up).
 *
 * Start-up (3.4.1): on 0 <= t <= dt only tau moves, by (3.26) from
 * tau(0) = 0, the others held at 0; that segment is the history of the
 * delay equation after dt. As one delay equation from t = 0: the
 * history before 0 is 0 and T0, T, gamma are frozen until dt. */
typedef struct cm_chip_bue {
    double a, b, n, T_Phi, eps, dt, eta, zeta, H, Omega;
} cm_chip_bue;

/* The thesis' Sec. 3.4.1 values: a 0.3, b 0.012, n 0.2, T_Phi 1.2,
 * eps 2.44, dt 0.4, eta 4, zeta 30, H 0.1, Omega 0.18. */
cm_chip_bue cm_chip_bue_defaults(void);

/* The strain rate F (3.22) at temperature T (> -1), stress tau, strain gamma. */
double cm_chip_bue_rate(const cm_chip_bue *c, double T, double tau, double gamma);

/* c as a delay equation from t = 0 (d->ctx = c, which must outlive d;
 * method rk8pd, tolerances 1e-9). */
void cm_chip_bue_dde(const cm_chip_bue *c, cm_dde *d);

/* chip-bue's parameters as the commands take them (the coefficients
 * above, dt the delay, and the integrator's method, abs_tol, rel_tol). */
extern const cm_param_spec cm_chip_bue_spec[];

/* c and d (as cm_chip_bue_dde, with the integrator settings) from values
 * p of cm_chip_bue_spec. */
void cm_chip_bue_of(const cm_params *p, cm_chip_bue *c, cm_dde *d);

/* The names of chip-bue's coordinates: T0, T, gamma, tau. */
extern const char *const cm_chip_bue_coords[4];

/* chip-bue's values from command-line texts ("k=v,..." each) over its
 * defaults: CM_EINVAL (msg: which and its range) for a bad one. */
cm_status cm_chip_bue_params(const char *const *texts, int n_texts, cm_params *p, char *msg,
                             size_t msg_size);

/* m describes chip-bue at values p for the reports (its name, values and
 * the 4 coordinates' names); it has no map (step NULL). */
void cm_chip_bue_describe(const cm_params *p, cm_model *m);
