/* realpath() is XSI */
#define _XOPEN_SOURCE 700

#include "models/registry.h"

#include <dlfcn.h>
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/models.h"
#include "models/ode_flow.h"
#include "models/params.h"

/* The left region of the thesis' C-SCM example (4.6.3): it holds the chaotic
 * attractors at SW_1..SW_3 on the x-axis (x = m/P). */
#define CM_PD_EXAMPLE_REGION "0:500,-40:40"
/* Fig. 4.30: the attractors at SW_-4..SW_4 (x = m/P, |m/P| < 73000) and
 * the sticking zones around the fixed points between them. */
#define CM_PD_FRICTION_REGION "-100000:100000,-300:300"
/* The attractors of the thesis' parameter points (|x| < 2 at Omega = 0.5). */
#define CM_FO_REGION "-3:3,-3:3"
/* The attractors of chip-4d on its section (xi 3.5 to 11 at zeta = 21:
 * tau2 1.00-1.15, T1 0.190-0.214, T2 0.245-0.30). */
#define CM_CHIP_REGION "0.9:1.25,0.15:0.25,0.2:0.35"
/* chip-workpiece's largest deflections at f = 1 (z up to about 21). */
#define CM_CHIP_WORKPIECE_REGION "0:2,0:1,0:1.5,0:2.5,0:25"

static const cm_model_entry entries[] = {
    {"microchaos-1d", "x = x_j", "1D micro-chaos map x' = a x - b Int(x) (4.1)", "-15:15",
     cm_microchaos_1d_spec, cm_microchaos_1d_create},
    {"microchaos-1d-friction", "x = x_j", "1D transient micro-chaos map with Coulomb friction (4.23)",
     "-2:2", cm_microchaos_1d_friction_spec, cm_microchaos_1d_friction_create},
    {"microchaos-delay", "x_lag1 = x_{j-1}, x = x_j", "2D micro-chaos map with delay (4.37)", "-6:6,-6:6",
     cm_microchaos_delay_spec, cm_microchaos_delay_create},
    {"microchaos-pd", "x, v = x' (dimensionless velocity)", "PD-controlled inverted pendulum, output quantisation (4.66)",
     CM_PD_EXAMPLE_REGION, cm_microchaos_pd_spec, cm_microchaos_pd_create},
    {"microchaos-pd-twofold", "x, v = x' (dimensionless velocity)", "PD map with twofold (input and output) quantisation (4.84)",
     CM_PD_EXAMPLE_REGION, cm_microchaos_pd_twofold_spec, cm_microchaos_pd_twofold_create},
    {"microchaos-pd-friction", "x, v = x' (dimensionless velocity)",
     "PD map with dry friction: hybrid micro-chaos map, sticking zones (4.81)",
     CM_PD_FRICTION_REGION, cm_microchaos_pd_friction_spec, cm_microchaos_pd_friction_create},
    {"microchaos-general", "x_lagd = x_{j-d}, ..., x_lag1 = x_{j-1}, x = x_j (d: the delay)",
     "n-D micro-chaos map with delays; output, input or twofold quantisation (4.9, C.14, C.17)",
     NULL, cm_microchaos_general_spec, cm_microchaos_general_create},
    {"friction-oscillator", "x, v (position and velocity at the section)",
     "Poincare map of the harmonically excited oscillator with dry friction (2.3), docs/models.md 9",
     CM_FO_REGION, cm_friction_oscillator_spec, cm_friction_oscillator_create},
    {"duffing", "x, v (position and velocity at the forcing phase)",
     "stroboscopic map of the forced Duffing oscillator x'' + delta x' - x + x^3 = gamma cos(omega t), integrated by GSL",
     "-2.5:2.5,-2.5:2.5", cm_duffing_spec, cm_duffing_create},
    {"chip-4d", "tau2, T1, T2 (stress and temperatures where the flow crosses the plane T0 = 0.1 downwards)",
     "Poincare map of Palmai's chip formation flow (3.27)-(3.31), integrated by GSL",
     CM_CHIP_REGION, cm_chip_4d_spec, cm_chip_4d_create},
    {"chip-workpiece",
     "tau2, T0, T1, T2, z (where the workpiece's velocity v crosses 0 downwards: its largest deflections)",
     "Poincare map of chip formation on an elastic workpiece (3.12)-(3.16), integrated by GSL",
     CM_CHIP_WORKPIECE_REGION, cm_chip_workpiece_spec, cm_chip_workpiece_create},
};

size_t cm_model_count(void) { return sizeof entries / sizeof entries[0]; }

const cm_model_entry *cm_model_at(size_t i) { return i < cm_model_count() ? &entries[i] : NULL; }

const cm_model_entry *cm_model_find(const char *name) { return cm_model_set_find(NULL, name, NULL); }

const cm_model_entry *cm_model_set_find(const cm_model_set *s, const char *name,
                                        const cm_model_lib **lib)
{
    if (lib)
        *lib = NULL;
    for (size_t i = 0; i < cm_model_count(); i++)
        if (strcmp(entries[i].name, name) == 0)
            return &entries[i];
    for (int k = 0; s && k < s->n; k++)
        for (int i = 0; i < s->lib[k].plugin->count; i++)
            if (strcmp(s->lib[k].plugin->models[i].name, name) == 0) {
                if (lib)
                    *lib = &s->lib[k];
                return &s->lib[k].plugin->models[i];
            }
    return NULL;
}

size_t cm_model_set_count(const cm_model_set *s)
{
    size_t n = cm_model_count();
    for (int k = 0; s && k < s->n; k++)
        n += (size_t)s->lib[k].plugin->count;
    return n;
}

const cm_model_entry *cm_model_set_at(const cm_model_set *s, size_t i)
{
    if (i < cm_model_count())
        return &entries[i];
    i -= cm_model_count();
    for (int k = 0; s && k < s->n; i -= (size_t)s->lib[k++].plugin->count)
        if (i < (size_t)s->lib[k].plugin->count)
            return &s->lib[k].plugin->models[i];
    return NULL;
}

cm_status cm_file_hash(const char *path, char out[24], char *msg, size_t msg_size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return cm_fail(CM_EIO, msg, msg_size, "cannot read %s: %s", path, strerror(errno));
    uint64_t h = UINT64_C(0xcbf29ce484222325);
    unsigned char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        for (size_t i = 0; i < n; i++)
            h = (h ^ buf[i]) * UINT64_C(0x100000001b3);
    const bool failed = ferror(f);
    fclose(f);
    if (failed)
        return cm_fail(CM_EIO, msg, msg_size, "cannot read %s", path);
    snprintf(out, 24, "%016llx", (unsigned long long)h);
    return CM_OK;
}

cm_status cm_model_set_load(cm_model_set *s, const char *path, char *msg, size_t msg_size)
{
    char hash[24], full[CM_MODEL_LIB_PATH + 2];
    if (strlen(path) >= CM_MODEL_LIB_PATH)
        return cm_fail(CM_EINVAL, msg, msg_size, "the plugin path is too long");
    /* dlopen searches the library path for a bare name: "./" makes it a file */
    snprintf(full, sizeof full, "%s%s", strchr(path, '/') ? "" : "./", path);
    cm_status st = cm_file_hash(full, hash, msg, msg_size);
    if (st != CM_OK)
        return st;
    for (int k = 0; k < s->n; k++)
        if (strcmp(s->lib[k].hash, hash) == 0)
            return CM_OK;
    if (s->n == CM_MODEL_LIBS_MAX)
        return cm_fail(CM_EINVAL, msg, msg_size, "at most %d plugins", CM_MODEL_LIBS_MAX);
    void *h = dlopen(full, RTLD_NOW | RTLD_LOCAL);
    if (!h)
        return cm_fail(CM_EINVAL, msg, msg_size, "cannot load plugin %s: %s", path, dlerror());
    cm_plugin_entry entry;
    *(void **)&entry = dlsym(h, CM_PLUGIN_ENTRY_NAME);
    const cm_plugin *p = entry ? entry() : NULL;
    if (!p) {
        dlclose(h);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%s is no cellmap plugin: it exports no %s() (see examples/plugin/)", path,
                       CM_PLUGIN_ENTRY_NAME);
    }
    if (p->abi < CM_PLUGIN_ABI_OLDEST || p->abi > CM_PLUGIN_ABI) {
        const int abi = p->abi; /* read before the library is unmapped */
        dlclose(h);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "plugin %s was built for plugin ABI %d, this cellmap loads ABI %d..%d: "
                       "build it again against this cellmap's headers",
                       path, abi, CM_PLUGIN_ABI_OLDEST, CM_PLUGIN_ABI);
    }
    if (p->count < 0 || (p->count > 0 && !p->models)) {
        dlclose(h);
        return cm_fail(CM_EINVAL, msg, msg_size, "plugin %s lists no models", path);
    }
    for (int i = 0; i < p->count; i++) {
        const char *problem = !p->models[i].name || !p->models[i].params || !p->models[i].create
                                  ? "lacks a name, params or create()"
                              : cm_model_set_find(s, p->models[i].name, NULL)
                                  ? "has the name of a model cellmap knows already; rename it"
                                  : NULL;
        if (problem) {
            char name[64];
            snprintf(name, sizeof name, "%s", p->models[i].name ? p->models[i].name : "?");
            dlclose(h); /* the names live in the library: copied first */
            return cm_fail(CM_EINVAL, msg, msg_size, "plugin %s: model %d (%s) %s", path, i + 1,
                           name, problem);
        }
    }
    cm_model_lib *l = &s->lib[s->n++];
    l->handle = h;
    char *absolute = realpath(full, NULL); /* files record it: any directory finds it */
    snprintf(l->path, sizeof l->path, "%s", absolute ? absolute : path);
    free(absolute);
    memcpy(l->hash, hash, sizeof l->hash);
    l->plugin = p;
    return CM_OK;
}

void cm_model_set_close(cm_model_set *s)
{
    for (int k = 0; k < s->n; k++)
        dlclose(s->lib[k].handle);
    memset(s, 0, sizeof *s);
}

cm_status cm_model_create(const char *name, const char *const *texts, int n_texts, cm_model *m,
                          char *msg, size_t msg_size)
{
    return cm_model_set_create(NULL, name, texts, n_texts, m, msg, msg_size);
}

cm_status cm_model_set_create(const cm_model_set *s, const char *name, const char *const *texts,
                              int n_texts, cm_model *m, char *msg, size_t msg_size)
{
    memset(m, 0, sizeof *m);
    const cm_model_entry *e = cm_model_set_find(s, name, NULL);
    if (!e)
        return cm_fail(CM_ENOTFOUND, msg, msg_size,
                       "unknown model '%s' (`cellmap models` lists them; a model of your own "
                       "comes with --model-lib PLUGIN.so)",
                       name);
    cm_params p;
    cm_status st = cm_params_defaults(e->params, &p, msg, msg_size);
    for (int i = 0; st == CM_OK && i < n_texts; i++)
        st = cm_params_set(&p, texts[i], msg, msg_size);
    if (st == CM_OK && msg && msg_size)
        msg[0] = 0;
    if (st == CM_OK)
        st = e->create(&p, m, msg, msg_size);
    if (st != CM_OK && msg && msg_size && !msg[0]) /* a plugin that said nothing */
        snprintf(msg, msg_size, "model %s: create() failed (status %d) and gave no reason", name,
                 (int)st);
    /* a plugin's flow becomes a map here; built-in ones attached theirs */
    if (st == CM_OK && m->flow.field && !m->step)
        st = cm_flow_attach(m, msg, msg_size);
    /* a plugin's model is checked as far as it can be before any step */
    if (st == CM_OK && (m->dim < 1 || m->dim > CM_MAX_DIM || !m->step || !m->name))
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "model %s: create() gave dimension %d%s; it must give 1..%d, a name and a "
                     "step function",
                     name, m->dim, m->step ? "" : " and no step function", CM_MAX_DIM);
    const cm_model_lib *lib = NULL;
    cm_model_set_find(s, name, &lib);
    if (st == CM_OK) /* a plugin's step is guarded: its status codes are checked */
        st = cm_model_wrap_periods(m, lib != NULL, msg, msg_size);
    /* Maps of delayed values name their state after the lags: ..., x_lag1, x */
    static const char *const lag_names[CM_MAX_DIM] = {"x_lag5", "x_lag4", "x_lag3",
                                                      "x_lag2", "x_lag1", "x"};
    if (st == CM_OK && !m->coord_names && m->dim >= 1 && m->dim <= CM_MAX_DIM) {
        m->coord_names = lag_names + (CM_MAX_DIM - m->dim);
        m->equal_axes = 1; /* delayed values of one variable share its unit */
    }
    if (st != CM_OK)
        cm_model_release(m);
    return st;
}
