/* cellmap/numtext.c - shortest round-trip decimal text of a double. */
#include "cellmap/numtext.h"

#include <ctype.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool reads_back(double v, double tol, int digits, char buf[CM_NUM_TEXT])
{
    snprintf(buf, CM_NUM_TEXT, "%.*g", digits, v);
    return fabs(strtod(buf, NULL) - v) <= tol;
}

char *cm_num_text(double v, char buf[CM_NUM_TEXT])
{
    return cm_num_text_near(v, 0, buf);
}

char *cm_num_text_near(double v, double tol, char buf[CM_NUM_TEXT])
{
    if (tol > 0 && fabs(v) <= tol)
        v = 0;
    if (!isfinite(v) || v == 0 || !(tol >= 0)) {
        snprintf(buf, CM_NUM_TEXT, "%g", v);
        return buf;
    }
    /* The first digit count that reads back is the shortest. (Bisection
     * would assume that n + 1 digits read back whenever n do, which fails
     * just below a power of two, where a double's rounding interval is
     * lopsided.) 17 digits always read back. */
    int digits = 1;
    while (digits < 17 && !reads_back(v, tol, digits, buf))
        digits++;
    reads_back(v, tol, digits, buf);
    /* Whole numbers as people write them: 125000, not 1.25e+05 (%g uses an
     * exponent once it exceeds the digits). Below 2^53 such a number is an
     * exact integer, so printing all its digits adds only zeros. */
    const char *e = strchr(buf, 'e');
    const int exponent = e ? atoi(e + 1) : 0;
    if (e && exponent >= digits && fabs(v) < 9007199254740992.0)
        reads_back(v, tol, exponent + 1, buf);
    return buf;
}

int cm_json_numbers_shortest(const char *json, char *out, size_t size)
{
    size_t used = 0;
    bool in_string = false;
    for (const char *p = json; *p;) {
        const bool starts_number =
            !in_string && (isdigit((unsigned char)*p) || (*p == '-' && isdigit((unsigned char)p[1])));
        if (starts_number) {
            char *end, text[CM_NUM_TEXT];
            const double v = strtod(p, &end);
            const size_t n = strlen(cm_num_text(v, text));
            if (used + n >= size)
                return 0;
            memcpy(out + used, text, n);
            used += n;
            p = end;
            continue;
        }
        if (*p == '"' && (p == json || p[-1] != '\\'))
            in_string = !in_string;
        if (used + 1 >= size)
            return 0;
        out[used++] = *p++;
    }
    out[used] = '\0';
    return 1;
}
