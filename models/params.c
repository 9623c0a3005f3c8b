#include "models/params.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int cm_params_find(const cm_params *p, const char *name)
{
    for (int i = 0; i < p->count; i++)
        if (strcmp(p->spec[i].name, name) == 0)
            return i;
    return -1;
}

double cm_params_get(const cm_params *p, const char *name)
{
    const int i = cm_params_find(p, name);
    return i >= 0 ? p->value[i].v[0] : NAN;
}

/* Index of word [w, w+len) in a '|'-separated choice list, or -1. */
static int choice_index(const char *choices, const char *w, size_t len)
{
    int index = 0;
    for (const char *c = choices; *c; index++) {
        const char *end = strchr(c, '|');
        const size_t clen = end ? (size_t)(end - c) : strlen(c);
        if (clen == len && strncmp(c, w, len) == 0)
            return index;
        if (!end)
            break;
        c = end + 1;
    }
    return -1;
}

static cm_status parse_value(const cm_param_spec *s, const char *text, size_t len,
                             cm_param_value *out, char *msg, size_t msg_size)
{
    if (s->choices) {
        const int k = choice_index(s->choices, text, len);
        if (k < 0)
            return cm_fail(CM_EINVAL, msg, msg_size, "parameter %s: '%.*s' is not one of %s",
                           s->name, (int)len, text, s->choices);
        out->count = 1;
        out->v[0] = k;
        return CM_OK;
    }
    char buf[2048];
    if (len == 0 || len >= sizeof buf)
        return cm_fail(CM_EINVAL, msg, msg_size, "parameter %s: empty or overlong value", s->name);
    memcpy(buf, text, len);
    buf[len] = '\0';
    int count = 0;
    for (char *tok = buf;; count++) {
        char *colon = strchr(tok, ':');
        if (colon)
            *colon = '\0';
        if (count >= s->max_count)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "parameter %s takes at most %d value%s (separate vector entries by ':')",
                           s->name, s->max_count, s->max_count == 1 ? "" : "s");
        char *end = NULL;
        errno = 0;
        const double v = strtod(tok, &end);
        if (end == tok || *end != '\0' || errno == ERANGE || !isfinite(v))
            return cm_fail(CM_EINVAL, msg, msg_size, "parameter %s: '%s' is not a finite number",
                           s->name, tok);
        if (v < s->min || v > s->max)
            return cm_fail(CM_ERANGE, msg, msg_size, "parameter %s = %g is outside [%g, %g]",
                           s->name, v, s->min, s->max);
        out->v[count] = v;
        if (!colon)
            break;
        tok = colon + 1;
    }
    out->count = count + 1;
    return CM_OK;
}

cm_status cm_params_defaults(const cm_param_spec *spec, cm_params *p, char *msg, size_t msg_size)
{
    memset(p, 0, sizeof *p);
    p->spec = spec;
    for (int i = 0; spec[i].name; i++) {
        if (i >= CM_MAX_PARAMS)
            return cm_fail(CM_EINVAL, msg, msg_size, "too many parameters in a model spec");
        cm_status st =
            parse_value(&spec[i], spec[i].def, strlen(spec[i].def), &p->value[i], msg, msg_size);
        if (st != CM_OK)
            return st;
        p->count = i + 1;
    }
    return CM_OK;
}

cm_status cm_params_set(cm_params *p, const char *text, char *msg, size_t msg_size)
{
    const char *s = text;
    while (*s) {
        const char *comma = strchr(s, ',');
        const size_t item_len = comma ? (size_t)(comma - s) : strlen(s);
        const char *eq = memchr(s, '=', item_len);
        if (!eq)
            return cm_fail(CM_EINVAL, msg, msg_size, "'%.*s' is not of the form name=value",
                           (int)item_len, s);
        int index = -1;
        for (int i = 0; i < p->count; i++)
            if (strlen(p->spec[i].name) == (size_t)(eq - s) &&
                strncmp(p->spec[i].name, s, (size_t)(eq - s)) == 0)
                index = i;
        if (index < 0)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "unknown parameter '%.*s' (see `cellmap models` for the names)",
                           (int)(eq - s), s);
        cm_status st = parse_value(&p->spec[index], eq + 1, item_len - (size_t)(eq + 1 - s),
                                   &p->value[index], msg, msg_size);
        if (st != CM_OK)
            return st;
        s += item_len;
        if (*s == ',')
            s++;
    }
    return CM_OK;
}

static bool listed(const char *name, const char *const *names)
{
    for (; names && *names; names++)
        if (strcmp(name, *names) == 0)
            return true;
    return false;
}

void cm_params_format_with(const cm_params *p, const char *const *skip, char *buf, size_t size)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < p->count && used < size; i++) {
        if (listed(p->spec[i].name, skip))
            continue;
        used +=
            (size_t)snprintf(buf + used, size - used, "%s%s=", used ? "," : "", p->spec[i].name);
        for (int k = 0; k < p->value[i].count && used < size; k++) {
            if (p->spec[i].choices) {
                char word[64];
                cm_param_choice_name(p->spec[i].choices, (int)p->value[i].v[k], word,
                                     sizeof word);
                used += (size_t)snprintf(buf + used, size - used, "%s", word);
            } else {
                char text[CM_NUM_TEXT];
                used += (size_t)snprintf(buf + used, size - used, "%s%s", k ? ":" : "",
                                         cm_num_text(p->value[i].v[k], text));
            }
        }
    }
}

void cm_params_format(const cm_params *p, char *buf, size_t size)
{
    cm_params_format_with(p, NULL, buf, size);
}

cm_status cm_model_setup(cm_model *m, const char *name, int dim, const cm_params *p,
                         size_t ctx_size, char *msg, size_t msg_size)
{
    memset(m, 0, sizeof *m);
    m->ctx = calloc(1, ctx_size);
    if (!m->ctx)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory building model %s", name);
    m->name = name;
    m->dim = dim;
    m->params = p->spec;
    m->values = *p;
    m->destroy = free;
    return CM_OK;
}
