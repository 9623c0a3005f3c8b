/* src/attractor_opts.c - the attractor options (src/attractor_opts.h). */
#include "src/attractor_opts.h"

#include <math.h>
#include <string.h>

bool attractor_options_take(cli *c, cm_attractor_options *o, int *error)
{
    if (cli_is(c, "--attractor-steps", true, error)) {
        double v[3] = {0, 0, 0};
        int n = 0;
        bool ok = c->value && parse_doubles(c->value, v, &n, 3) && n >= 2;
        for (int k = 0; ok && k < n; k++)
            ok = v[k] >= (k == 1 ? 8 : k == 2 ? 1 : 0) && v[k] <= UINT32_MAX && v[k] == floor(v[k]);
        if (c->value && !ok)
            *error = cli_usage_error(c, "--attractor-steps: '%s' must be T,R or T,R,MAX (whole "
                                        "numbers of steps, R at least 8)", c->value);
        if (ok) { /* converted only when in range: a negative count is no uint32_t */
            o->transient = (uint32_t)v[0];
            o->record = (uint32_t)v[1];
            o->max_steps = (uint32_t)v[2];
        }
    } else if (cli_is(c, "--attractor-tol", true, error)) {
        double v[2] = {0, 0};
        int n = 0;
        if (c->value && (!parse_doubles(c->value, v, &n, 2) || !(v[0] > 0) ||
                         (n == 2 && !(v[1] > 0))))
            *error = cli_usage_error(c, "--attractor-tol: '%s' must be TOL or TOL,MATCH, each "
                                        "above 0 (cell widths)", c->value);
        o->tol = v[0];
        o->match = n == 2 ? v[1] : 0;
    } else if (cli_is(c, "--outside-steps", true, error)) {
        double v = 0;
        int n = 0;
        const bool ok = c->value && parse_doubles(c->value, &v, &n, 1) && n == 1 && v >= 0 &&
                        v <= CM_OUTSIDE_MAX_STEPS && v == floor(v);
        if (c->value && !ok)
            *error = cli_usage_error(c, "--outside-steps: '%s' must be a whole number of steps "
                                        "from 0 (not followed) to %u", c->value,
                                     CM_OUTSIDE_MAX_STEPS);
        if (ok)
            o->outside = v == 0 ? CM_OUTSIDE_OFF : (uint32_t)v;
    } else {
        return false;
    }
    /* the options together, for every command that takes them: a bad
     * budget or tolerance is the user's, before any work */
    cm_attractor_options all;
    char why[256];
    cm_attractor_defaults(NULL, o, &all);
    if (!*error && cm_attractor_check(&all, why, sizeof why) != CM_OK)
        *error = cli_usage_error(c, "%s: %s", c->opt, why);
    return true;
}

bool by_option_take(cli *c, int *by, int *error)
{
    if (!cli_is(c, "--by", true, error))
        return false;
    if (c->value && strcmp(c->value, "groups") == 0)
        *by = BY_GROUPS;
    else if (c->value && strcmp(c->value, "attractors") == 0)
        *by = BY_ATTRACTORS;
    else if (c->value)
        *error = cli_usage_error(c, "--by: '%s' must be attractors (the system's, by true "
                                    "orbits) or groups (cell mapping's)", c->value);
    return true;
}
