/* lib/param_grid.c - parameter axes and sweeps (lib/param_grid.h). */
#include "lib/param_grid.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/store.h"
#include "lib/parse.h"
#include "models/registry.h"

/* NAME=V1,V2,... after the '=' */
static bool parse_list(const char *text, param_axis *a)
{
    if (!parse_doubles(text, a->values, &a->n, PARAM_AXIS_MAX) || a->n < 1)
        return false;
    for (int k = 0; k < a->n; k++)
        if (!isfinite(a->values[k]) || (k > 0 && !(a->values[k] > a->values[k - 1])))
            return false;
    const double *v = a->values;
    const int n = a->n;
    const double first = n > 1 ? v[1] - v[0] : fmax(fabs(v[0]) * 1e-3, 1e-9);
    const double last = n > 1 ? v[n - 1] - v[n - 2] : first;
    a->lo = v[0] - first / 2;
    a->hi = v[n - 1] + last / 2;
    a->listed = true;
    return true;
}

bool param_axis_parse(const char *s, size_t len, param_axis *a)
{
    char buf[PARAM_AXIS_MAX * 32];
    if (len >= sizeof buf)
        return false;
    memcpy(buf, s, len);
    buf[len] = 0;
    char *eq = strchr(buf, '=');
    if (!eq || eq == buf || (size_t)(eq - buf) >= sizeof a->name)
        return false;
    *eq = 0;
    memcpy(a->name, buf, (size_t)(eq - buf) + 1);
    a->listed = false;
    if (!strchr(eq + 1, ':'))
        return parse_list(eq + 1, a);
    char *end;
    a->lo = strtod(eq + 1, &end);
    if (*end != ':')
        return false;
    a->hi = strtod(end + 1, &end);
    if (*end != ':')
        return false;
    const long n = strtol(end + 1, &end, 10);
    a->n = (int)n;
    return *end == 0 && n >= 1 && n <= PARAM_AXIS_MAX && isfinite(a->lo) && isfinite(a->hi) &&
           a->lo < a->hi;
}

bool param_axes_parse2(const char *s, param_axis ax[2])
{
    const char *eq = strchr(s, '='), *second = eq ? strchr(eq + 1, '=') : NULL;
    const char *comma = second ? second : NULL;
    while (comma && comma > s && *comma != ',')
        comma--;
    return comma && *comma == ',' && param_axis_parse(s, (size_t)(comma - s), &ax[0]) &&
           param_axis_parse(comma + 1, strlen(comma + 1), &ax[1]);
}

double param_axis_value(const param_axis *a, int i)
{
    if (a->listed)
        return a->values[i];
    return a->lo + (i + 0.5) * (a->hi - a->lo) / a->n;
}

bool param_axis_even(const param_axis *a)
{
    if (!a->listed || a->n < 3)
        return true;
    const double step = (a->values[a->n - 1] - a->values[0]) / (a->n - 1);
    for (int k = 1; k < a->n; k++)
        if (fabs(a->values[k] - a->values[k - 1] - step) > 1e-9 * step)
            return false;
    return true;
}

void param_axes_format(const param_axis *ax, int n_ax, char *out, size_t size)
{
    size_t used = 0;
    out[0] = 0;
    for (int k = 0; k < n_ax && used < size; k++) {
        used += (size_t)snprintf(out + used, size - used, "%s%s=", k ? "," : "", ax[k].name);
        if (!ax[k].listed)
            used += (size_t)snprintf(out + used, used < size ? size - used : 0, "%s:%s:%d",
                                     CM_NUM(ax[k].lo), CM_NUM(ax[k].hi), ax[k].n);
        for (int i = 0; ax[k].listed && i < ax[k].n && used < size; i++)
            used += (size_t)snprintf(out + used, size - used, "%s%s", i ? "," : "",
                                     CM_NUM(ax[k].values[i]));
    }
}

void param_axes_json(json *j, const char *key, const param_axis *ax, int n_ax)
{
    json_array(j, key);
    for (int k = 0; k < n_ax; k++) {
        json_object(j, NULL);
        json_str(j, "name", ax[k].name);
        json_num(j, "lo", ax[k].lo);
        json_num(j, "hi", ax[k].hi);
        json_uint(j, "n", (uint64_t)ax[k].n);
        if (ax[k].listed)
            json_nums(j, "values", ax[k].values, ax[k].n);
        json_object_end(j);
    }
    json_array_end(j);
}

void param_base_json(json *j, const char *model, const cm_params *base)
{
    char params[4096];
    cm_params_json(base, params, sizeof params);
    json_str(j, "model", model);
    json_raw(j, "params", params);
}

/* Whether name is one of the list "a or b or c". */
static bool name_listed(const char *name, const char *list)
{
    const size_t n = strlen(name);
    for (const char *p = list;; p += 4) {
        if (strncmp(p, name, n) == 0 && (p[n] == '\0' || p[n] == ' '))
            return true;
        if (!(p = strstr(p, " or ")))
            return false;
    }
}

cm_status param_sweep_base(const model_spec *mo, const char *only, const param_axis *ax,
                           int n_ax, cm_params *base, char *msg, size_t msg_size)
{
    const cm_model_entry *e = cm_model_set_find(&mo->set, mo->name, NULL);
    if (!e)
        return cm_fail(CM_EINVAL, msg, msg_size, "unknown model '%s' (`cellmap models` lists them)",
                       mo->name);
    if (only && !name_listed(e->name, only))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "model %s: this command is implemented for %s only", e->name, only);
    cm_status st = cm_params_defaults(e->params, base, msg, msg_size);
    for (int k = 0; k < mo->n_texts && st == CM_OK; k++)
        st = cm_params_set(base, mo->texts[k], msg, msg_size);
    if (st != CM_OK)
        return st;
    for (int k = 0; k < n_ax; k++)
        if (cm_params_find(base, ax[k].name) < 0)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "'%s' is not a parameter of %s (`cellmap models`)", ax[k].name,
                           e->name);
    return CM_OK;
}

bool model_with_values(const model_spec *mo, const char *const *names, const double *values, int n,
                       cm_model *m, char *msg, size_t msg_size)
{
    const char *texts[MODEL_SPEC_TEXTS + 2];
    char value_text[2][80];
    int k = 0;
    for (int i = 0; i < mo->n_texts; i++)
        texts[k++] = mo->texts[i];
    for (int i = 0; i < n && i < 2; i++) {
        snprintf(value_text[i], sizeof value_text[i], "%s=%s", names[i], CM_NUM(values[i]));
        texts[k++] = value_text[i];
    }
    return cm_model_set_create(&mo->set, mo->name, texts, k, m, msg, msg_size) == CM_OK;
}

cm_status param_number(const cm_model *m, const char *name, const char *what, double *v,
                       char *msg, size_t msg_size)
{
    const int k = cm_params_find(&m->values, name);
    if (k < 0 || m->values.spec[k].max_count != 1 || m->values.spec[k].choices)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%s '%s' is not a number parameter of model %s (`cellmap models` lists "
                       "them)",
                       what, name, m->name);
    *v = m->values.value[k].v[0];
    return CM_OK;
}

cm_status branch_spec_check(const branch_spec *b, const cm_model *m, double *p0, char *msg,
                            size_t msg_size)
{
    *p0 = NAN;
    if (!b->name[0])
        return CM_OK;
    const cm_status st = param_number(m, b->name, "the branch's parameter", p0, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (!(b->lo < b->hi && isfinite(b->lo) && isfinite(b->hi)) || *p0 < b->lo || *p0 > b->hi)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the branch's range %s=%g:%g must hold the model's %s = %g (set it with "
                       "the parameters, e.g. %s=%g)",
                       b->name, b->lo, b->hi, b->name, *p0, b->name, 0.5 * (b->lo + b->hi));
    return CM_OK;
}

cm_status param_model_at(void *user, double p, cm_model *m, char *msg, size_t msg_size)
{
    const param_builder *b = user;
    return model_with_values(b->mo, b->names, &p, 1, m, msg, msg_size) ? CM_OK : CM_EINVAL;
}

cm_status param_model_at2(void *user, double p, double q, cm_model *m, char *msg,
                          size_t msg_size)
{
    const param_builder *b = user;
    const double values[2] = {p, q};
    return model_with_values(b->mo, b->names, values, 2, m, msg, msg_size) ? CM_OK : CM_EINVAL;
}

bool model_at_point(const model_spec *mo, const param_axis *ax, const int *idx, int n_ax,
                    cm_model *m)
{
    const char *names[2];
    double values[2];
    for (int k = 0; k < n_ax && k < 2; k++) {
        names[k] = ax[k].name;
        values[k] = param_axis_value(&ax[k], idx[k]);
    }
    char msg[256];
    return model_with_values(mo, names, values, n_ax < 2 ? n_ax : 2, m, msg, sizeof msg);
}
