/* tests/test_numtext.c - shortest round-trip number text (cm_num_text) and
 * the rewriting of older files' 17-digit parameter JSON. */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/numtext.h"
#include "check.h"
#include "mix.h"

/* Significant digits of a %g-style text: digits of the mantissa without
 * leading zeros, nor the trailing zeros of a whole number (125000: 3). */
static int significant_digits(const char *s)
{
    int n = 0, zeros = 0;
    bool leading = true;
    for (; *s && *s != 'e'; s++) {
        if (*s < '0' || *s > '9')
            continue;
        if (*s != '0')
            leading = false;
        if (!leading)
            n++;
        zeros = *s == '0' ? zeros + 1 : 0;
    }
    return strchr(s - n, '.') ? n : n - zeros;
}

/* The text reads back exactly, and no fewer digits would. */
static void check_shortest(double v)
{
    char text[CM_NUM_TEXT], shorter[400];
    cm_num_text(v, text);
    CHECK(strtod(text, NULL) == v);
    const int digits = significant_digits(text);
    CHECK(digits >= 1 && digits <= 17);
    for (int d = 1; d < digits; d++) {
        snprintf(shorter, sizeof shorter, "%.*g", d, v);
        if (strtod(shorter, NULL) == v) {
            fprintf(stderr, "%.17g: %s has %d digits but %s reads back\n", v, text, digits,
                    shorter);
            CHECK(0);
        }
    }
}

static void random_bit_patterns(void)
{
    for (uint64_t i = 0; i < 100000; i++) {
        const uint64_t bits = mix(i + 1);
        double v;
        memcpy(&v, &bits, sizeof v);
        if (isfinite(v))
            check_shortest(v);
    }
}

/* Values typed with few digits print with no more digits than typed; whole
 * numbers below 2^53 without an exponent. */
static void typed_values(void)
{
    for (uint64_t i = 0; i < 100000; i++) {
        const uint64_t h = mix(i + 1000003);
        const int digits = 1 + (int)(h % 15);
        const int exponent = (int)((h >> 8) % 41) - 20;
        char typed[400], text[CM_NUM_TEXT];
        snprintf(typed, sizeof typed, "%.*e", digits - 1, (double)(h >> 20) / 4503599627370496.0 * 9 + 1);
        snprintf(typed + strlen(typed) - 4, 8, "e%+d", exponent); /* replace e+00 */
        const double v = strtod(typed, NULL);
        cm_num_text(v, text);
        const bool whole = v == floor(v) && fabs(v) < 9007199254740992.0;
        if (strtod(text, NULL) != v || significant_digits(text) > digits ||
            (whole && strchr(text, 'e'))) {
            fprintf(stderr, "typed %s, printed %s\n", typed, text);
            CHECK(0);
        }
    }
}

/* The thesis' parameter values (Figs. 4.21, 4.25, §4.6.3, Ch. 2). */
static void thesis_values(void)
{
    static const struct {
        double v;
        const char *text;
    } cases[] = {
        {0.007, "0.007"},           {0.02, "0.02"},          {0.078, "0.078"},
        {0.07, "0.07"},             {6.8511e-3, "0.0068511"}, {5.4997e-5, "5.4997e-05"},
        {2.5665e-3, "0.0025665"},   {0.09, "0.09"},          {0.1, "0.1"},
        {85.4, "85.4"},             {-125000, "-125000"},    {1.0 / 3, "0.3333333333333333"},
        {0.1 + 0.2, "0.30000000000000004"}, {0, "0"},         {-0.0, "-0"},
        {5e-324, "5e-324"},         {1.7976931348623157e308, "1.7976931348623157e+308"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[CM_NUM_TEXT];
        cm_num_text(cases[i].v, text);
        if (strcmp(text, cases[i].text) != 0) {
            fprintf(stderr, "%.17g printed %s, expected %s\n", cases[i].v, text, cases[i].text);
            CHECK(0);
        }
    }
    CHECK(strcmp(CM_NUM(NAN), "nan") == 0);
    CHECK(strcmp(CM_NUM(-INFINITY), "-inf") == 0);
}

static void older_json(void)
{
    char out[256];
    CHECK(cm_json_numbers_shortest("{\"alpha\":0.078000000000000003,\"beta\":0,\"P\":0.0070000000000000001,"
                                   "\"D\":-0.02,\"mode\":\"x2\",\"v\":[1e-05,2.5]}",
                                   out, sizeof out));
    CHECK(strcmp(out, "{\"alpha\":0.078,\"beta\":0,\"P\":0.007,\"D\":-0.02,\"mode\":\"x2\","
                      "\"v\":[1e-05,2.5]}") == 0);
    CHECK(!cm_json_numbers_shortest("{\"P\":0.0070000000000000001}", out, 8));
}

int main(void)
{
    random_bit_patterns();
    typed_values();
    thesis_values();
    older_json();
    CHECK_DONE();
}
