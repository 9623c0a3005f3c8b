/* cellmap models: the models, their state names and parameters. */
#include <stdio.h>
#include <string.h>

#include "lib/project.h"
#include "src/args.h"
#include "src/commands.h"
#include "lib/json.h"

static const char models_help[] =
    "usage: cellmap models [--model-lib PLUGIN.so ...] [--json]\n\n"
    "Lists every model with its state (the coordinates' names, used for CSV, JSON\n"
    "and SQL columns) and parameters (name, default, range, meaning).\n"
    "Parameters are set with --param name=value[,name=value]; vectors as v1:v2:...\n"
    "docs/models.md describes each model. --model-lib (repeatable) adds the models\n"
    "of a plugin (examples/plugin/ shows how to write one); every command that\n"
    "takes --model takes --model-lib too. The built-up-edge delay model chip-bue,\n"
    "whose state is a function over its delay rather than a point (docs/models.md\n"
    "12.3), is not listed: `simulate --model chip-bue` and `exponents --model\n"
    "chip-bue` take it, and `cellmap help simulate` lists its parameters' use.\n";

static void print_text(const cm_model_entry *e, const cm_model *m)
{
    printf("%s\n  %s\n  state: ", e->name, e->doc);
    for (int d = 0; d < m->dim; d++)
        printf("%s%s", d ? ", " : "", cm_model_coord_name(m, d));
    printf("  (%s)\n", e->state);
    for (const cm_param_spec *s = e->params; s->name; s++) {
        if (s->choices)
            printf("    %-6s = %-20s one of %s; %s\n", s->name, s->def, s->choices, s->doc);
        else
            printf("    %-6s = %-20s [%s, %s]%s; %s\n", s->name, s->def, CM_NUM(s->min),
                   CM_NUM(s->max), s->max_count > 1 ? " (vector)" : "", s->doc);
    }
    printf("\n");
}

static void print_json_entry(json *j, const cm_model_entry *e, const cm_model *m)
{
    json_object(j, NULL);
    json_str(j, "name", e->name);
    json_str(j, "doc", e->doc);
    json_array(j, "state");
    for (int d = 0; d < m->dim; d++)
        json_str(j, NULL, cm_model_coord_name(m, d));
    json_array_end(j);
    json_str(j, "state_doc", e->state);
    json_array(j, "params");
    for (const cm_param_spec *s = e->params; s->name; s++) {
        json_object(j, NULL);
        json_str(j, "name", s->name);
        json_str(j, "default", s->def);
        if (s->choices) {
            json_str(j, "choices", s->choices);
        } else {
            json_num(j, "min", s->min);
            json_num(j, "max", s->max);
            json_uint(j, "max_count", (uint64_t)s->max_count);
        }
        json_str(j, "doc", s->doc);
        json_object_end(j);
    }
    json_array_end(j);
    json_object_end(j);
}

int cmd_models(int argc, char **argv)
{
    cli c = {"models", argc, argv, 0, NULL, NULL};
    int err = 0;
    bool as_json = false;
    cm_model_set set = {0};
    while (cli_next(&c) && !err) {
        if (strcmp(c.opt, "--help") == 0) {
            fputs(models_help, stdout);
            return EXIT_OK;
        } else if (cli_is(&c, "--json", false, &err)) {
            as_json = true;
        } else if (cli_is(&c, "--model-lib", true, &err)) {
            char msg[1400];
            if (c.value && cm_model_set_load(&set, c.value, msg, sizeof msg) != CM_OK)
                err = cli_usage_error(&c, "--model-lib: %s", msg);
        } else {
            err = cli_stray(&c);
        }
    }
    if (err)
        return err;
    json j;
    if (as_json) {
        json_begin(&j, stdout, "models");
        json_array(&j, "models");
    }
    for (size_t i = 0; i < cm_model_set_count(&set); i++) {
        const cm_model_entry *e = cm_model_set_at(&set, i);
        cm_model m; /* built from its defaults, for the names of its state */
        char msg[512];
        if (cm_model_set_create(&set, e->name, NULL, 0, &m, msg, sizeof msg) != CM_OK) {
            fprintf(stderr, "cellmap models: %s: %s\n", e->name, msg);
            return EXIT_FAIL;
        }
        if (as_json)
            print_json_entry(&j, e, &m);
        else
            print_text(e, &m);
        cm_model_release(&m);
    }
    if (as_json) {
        json_array_end(&j);
        json_end(&j);
    }
    return EXIT_OK;
}
