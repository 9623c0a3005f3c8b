/* tests/check.h - minimal assertions that print both sides on failure.
 * Each test program returns the number of failed checks (0 = pass). */
#ifndef CM_TESTS_CHECK_H
#define CM_TESTS_CHECK_H

#include <math.h>
#include <stdio.h>

static int check_failures = 0;

#define CHECK(cond)                                                                               \
    do {                                                                                          \
        if (!(cond)) {                                                                            \
            fprintf(stderr, "%s:%d: CHECK(%s) failed\n", __FILE__, __LINE__, #cond);             \
            check_failures++;                                                                     \
        }                                                                                         \
    } while (0)

#define CHECK_INT(a, b)                                                                           \
    do {                                                                                          \
        const long long va_ = (long long)(a), vb_ = (long long)(b);                               \
        if (va_ != vb_) {                                                                         \
            fprintf(stderr, "%s:%d: %s == %s failed: %lld vs %lld\n", __FILE__, __LINE__, #a, #b, \
                    va_, vb_);                                                                    \
            check_failures++;                                                                     \
        }                                                                                         \
    } while (0)

/* |a - b| <= tol * max(1, |b|) */
#define CHECK_NEAR(a, b, tol)                                                                     \
    do {                                                                                          \
        const double va_ = (a), vb_ = (b);                                                        \
        if (!(fabs(va_ - vb_) <= (tol) * fmax(1.0, fabs(vb_)))) {                                 \
            fprintf(stderr, "%s:%d: %s ~ %s failed: %.17g vs %.17g (tol %g)\n", __FILE__,        \
                    __LINE__, #a, #b, va_, vb_, (double)(tol));                                   \
            check_failures++;                                                                     \
        }                                                                                         \
    } while (0)

#define CHECK_DONE()                                                                              \
    do {                                                                                          \
        if (check_failures)                                                                       \
            fprintf(stderr, "%d check(s) failed\n", check_failures);                             \
        return check_failures ? 1 : 0;                                                            \
    } while (0)

#endif
