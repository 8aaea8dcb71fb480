/* cli.h: the option parsing every program shares, so that all of them reject
 * bad options the same way: one line on stderr, exit status 2. */
#ifndef PS_APP_CLI_H
#define PS_APP_CLI_H

#include <stdbool.h>
#include <stdint.h>

#include "core/status.h"

/* Exit statuses of every program (contract: 2 for any bad input). */
enum { PS_EXIT_OK = 0, PS_EXIT_USAGE = 2 };

/* A walk over argv. Long options take their value as `--opt V` or `--opt=V`. */
typedef struct ps_cli {
    const char *prog; /* program name used in messages */
    int argc;
    char **argv;
    int i;                /* index of the current argument */
    const char *inline_v; /* the V of --opt=V, if given that way */
} ps_cli;

ps_cli ps_cli_begin(const char *prog, int argc, char **argv);

/* Advances to the next argument; false at the end. After it, ps_cli_is(cli,
 * "--name") tests the option's name (ignoring an =V part) and
 * ps_cli_positional tells whether it is not an option at all. A lone "-" and
 * anything after "--" are positional. */
bool ps_cli_next(ps_cli *cli);
bool ps_cli_is(const ps_cli *cli, const char *name);
bool ps_cli_positional(const ps_cli *cli);
const char *ps_cli_arg(const ps_cli *cli);

/* The value of the current option (consuming the next argument unless it came
 * as --opt=V). Missing values set err. */
ps_status ps_cli_string(ps_cli *cli, const char **out, ps_error *err);
/* A finite number in [lo, hi]. */
ps_status ps_cli_double(ps_cli *cli, double lo, double hi, double *out, ps_error *err);
/* A decimal integer in [lo, hi]. */
ps_status ps_cli_int(ps_cli *cli, int64_t lo, int64_t hi, int64_t *out, ps_error *err);
/* One of `choices` (NULL-terminated); *out is its index. */
ps_status ps_cli_choice(ps_cli *cli, const char *const *choices, int *out, ps_error *err);
/* WxH with each side in [1, max_side]. */
ps_status ps_cli_size(ps_cli *cli, int max_side, int *w, int *h, ps_error *err);
/* A comma list of 1..max strictly ascending numbers in [lo, hi] ("0.1,0.5,2"),
 * into out[0..*count). */
ps_status ps_cli_ascending(ps_cli *cli, double lo, double hi, double *out, int max, int *count, ps_error *err);

/* Sets err for the current argument being unknown. */
ps_status ps_cli_unknown(const ps_cli *cli, ps_error *err);

/* Prints err's message as one line on stderr and returns PS_EXIT_USAGE. */
int ps_cli_fail(const ps_error *err);

#endif
