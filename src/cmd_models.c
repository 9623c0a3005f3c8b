#include <stdio.h>
#include <string.h>

#include "models/registry.h"
#include "src/args.h"
#include "src/commands.h"

int cmd_models(int argc, char **argv)
{
    cli c = {"models", argc, argv, 0, NULL, NULL};
    while (cli_next(&c)) {
        if (strcmp(c.opt, "--help") == 0) {
            printf("usage: cellmap models\n\nLists every model with its state, parameters "
                   "(name, default, range, meaning).\nParameters are set with --param "
                   "name=value[,name=value]; vectors as v1:v2:...\n");
            return EXIT_OK;
        }
        return cli_usage_error(&c, "unexpected argument '%s'", c.opt);
    }
    for (size_t i = 0; i < cm_model_count(); i++) {
        const cm_model_entry *e = cm_model_at(i);
        printf("%s\n  %s\n  state: %s\n", e->name, e->doc, e->state);
        for (const cm_param_spec *s = e->params; s->name; s++) {
            if (s->choices)
                printf("    %-6s = %-20s one of %s; %s\n", s->name, s->def, s->choices, s->doc);
            else
                printf("    %-6s = %-20s [%s, %s]%s; %s\n", s->name, s->def, CM_NUM(s->min), CM_NUM(s->max),
                       s->max_count > 1 ? " (vector)" : "", s->doc);
        }
        printf("\n");
    }
    return EXIT_OK;
}
