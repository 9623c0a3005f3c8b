#include "models/linalg.h"

#include <math.h>
#include <string.h>

#include "cellmap/lattice.h"

void cm_mat_mul(int n, int k, int m, const double *a, const double *b, double *c)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < m; j++) {
            double s = 0.0;
            for (int l = 0; l < k; l++)
                s += a[i * k + l] * b[l * m + j];
            c[i * m + j] = s;
        }
}

void cm_mat_vec(int n, int m, const double *a, const double *x, double *y)
{
    for (int i = 0; i < n; i++) {
        double s = 0.0;
        for (int j = 0; j < m; j++)
            s += a[i * m + j] * x[j];
        y[i] = s;
    }
}

bool cm_mat_inverse(int n, const double *a, double *inv)
{
    double w[CM_MAX_DIM * CM_MAX_DIM];
    double scale = 0.0;
    memcpy(w, a, sizeof(double) * (size_t)(n * n));
    for (int i = 0; i < n * n; i++)
        scale = fmax(scale, fabs(a[i]));
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            inv[i * n + j] = i == j ? 1.0 : 0.0;
    for (int col = 0; col < n; col++) {
        int pivot = col;
        for (int r = col + 1; r < n; r++)
            if (fabs(w[r * n + col]) > fabs(w[pivot * n + col]))
                pivot = r;
        if (!(fabs(w[pivot * n + col]) > 1e-14 * scale))
            return false;
        for (int j = 0; j < n; j++) {
            double t = w[col * n + j];
            w[col * n + j] = w[pivot * n + j];
            w[pivot * n + j] = t;
            t = inv[col * n + j];
            inv[col * n + j] = inv[pivot * n + j];
            inv[pivot * n + j] = t;
        }
        const double p = w[col * n + col];
        for (int j = 0; j < n; j++) {
            w[col * n + j] /= p;
            inv[col * n + j] /= p;
        }
        for (int r = 0; r < n; r++) {
            if (r == col)
                continue;
            const double f = w[r * n + col];
            for (int j = 0; j < n; j++) {
                w[r * n + j] -= f * w[col * n + j];
                inv[r * n + j] -= f * inv[col * n + j];
            }
        }
    }
    return true;
}
