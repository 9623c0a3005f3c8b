/* models/chip_formation.h - the chip formation flows of the thesis'
 * Chapter 3 (docs/models.md 12): their coefficients and the constitutive
 * law (3.31) shared by the flows, for the analyses that need more than
 * the field. */
#ifndef CM_MODELS_CHIP_FORMATION_H
#define CM_MODELS_CHIP_FORMATION_H

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
