/* cli.c: shared option parsing. */
#include "app/cli.h"

#include "core/number.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

ps_cli ps_cli_begin(const char *prog, int argc, char **argv)
{
    ps_cli c = {prog, argc, argv, 0, NULL};
    return c;
}

static bool after_dashdash(const ps_cli *cli)
{
    for (int k = 1; k < cli->i; k++)
        if (strcmp(cli->argv[k], "--") == 0)
            return true;
    return false;
}

bool ps_cli_next(ps_cli *cli)
{
    cli->i++;
    cli->inline_v = NULL;
    if (cli->i < cli->argc && strcmp(cli->argv[cli->i], "--") == 0 && !after_dashdash(cli))
        cli->i++;
    if (cli->i >= cli->argc)
        return false;
    const char *a = cli->argv[cli->i];
    if (!ps_cli_positional(cli) && a[1] == '-') {
        const char *eq = strchr(a, '=');
        if (eq)
            cli->inline_v = eq + 1;
    }
    return true;
}

const char *ps_cli_arg(const ps_cli *cli) { return cli->argv[cli->i]; }

bool ps_cli_positional(const ps_cli *cli)
{
    const char *a = cli->argv[cli->i];
    return a[0] != '-' || a[1] == '\0' || after_dashdash(cli);
}

bool ps_cli_is(const ps_cli *cli, const char *name)
{
    if (ps_cli_positional(cli))
        return false;
    const char *a = cli->argv[cli->i];
    size_t n = strlen(name);
    return strncmp(a, name, n) == 0 && (a[n] == '\0' || (a[n] == '=' && a[1] == '-'));
}

/* The option's name without any =V, for messages. */
static int name_len(const ps_cli *cli)
{
    const char *a = cli->argv[cli->i];
    const char *eq = cli->inline_v ? cli->inline_v - 1 : NULL;
    return eq ? (int)(eq - a) : (int)strlen(a);
}

ps_status ps_cli_string(ps_cli *cli, const char **out, ps_error *err)
{
    if (cli->inline_v) {
        *out = cli->inline_v;
        return PS_OK;
    }
    if (cli->i + 1 >= cli->argc)
        return ps_error_set(err, PS_ERR_PARSE, "%s: option %s needs a value (see --help)", cli->prog,
                            cli->argv[cli->i]);
    cli->i++;
    *out = cli->argv[cli->i];
    return PS_OK;
}

/* The current option's name (length n, for messages) and value. */
static ps_status fetch(ps_cli *cli, int *n, const char **opt, const char **value, ps_error *err)
{
    *n = name_len(cli);
    *opt = cli->argv[cli->i];
    return ps_cli_string(cli, value, err);
}

ps_status ps_cli_double(ps_cli *cli, double lo, double hi, double *out, ps_error *err)
{
    int n;
    const char *opt, *s;
    ps_status st = fetch(cli, &n, &opt, &s, err);
    if (st != PS_OK)
        return st;
    double v;
    if (!ps_parse_double(s, &v))
        return ps_error_set(err, PS_ERR_PARSE, "%s: option %.*s: '%s' is not a finite number", cli->prog, n, opt, s);
    if (v < lo || v > hi)
        return ps_error_set(err, PS_ERR_RANGE, "%s: option %.*s: %s is outside [%g, %g]", cli->prog, n, opt, s, lo,
                            hi);
    *out = v;
    return PS_OK;
}

ps_status ps_cli_int(ps_cli *cli, int64_t lo, int64_t hi, int64_t *out, ps_error *err)
{
    int n;
    const char *opt, *s;
    ps_status st = fetch(cli, &n, &opt, &s, err);
    if (st != PS_OK)
        return st;
    int64_t v;
    if (!ps_parse_int64(s, &v))
        return ps_error_set(err, PS_ERR_PARSE, "%s: option %.*s: '%s' is not an integer", cli->prog, n, opt, s);
    if (v < lo || v > hi)
        return ps_error_set(err, PS_ERR_RANGE, "%s: option %.*s: %s is outside [%lld, %lld]", cli->prog, n, opt, s,
                            (long long)lo, (long long)hi);
    *out = v;
    return PS_OK;
}

ps_status ps_cli_choice(ps_cli *cli, const char *const *choices, int *out, ps_error *err)
{
    int n;
    const char *opt, *s;
    ps_status st = fetch(cli, &n, &opt, &s, err);
    if (st != PS_OK)
        return st;
    char list[256] = "";
    for (int k = 0; choices[k]; k++) {
        if (strcmp(s, choices[k]) == 0) {
            *out = k;
            return PS_OK;
        }
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%s", k ? "|" : "", choices[k]);
    }
    return ps_error_set(err, PS_ERR_PARSE, "%s: option %.*s: '%s' is not one of %s", cli->prog, n, opt, s, list);
}

ps_status ps_cli_size(ps_cli *cli, int max_side, int *w, int *h, ps_error *err)
{
    int n;
    const char *opt, *s;
    ps_status st = fetch(cli, &n, &opt, &s, err);
    if (st != PS_OK)
        return st;
    const char *x = strchr(s, 'x');
    char a[32], b[32];
    int64_t wv, hv;
    if (!x || (size_t)(x - s) >= sizeof a || strlen(x + 1) >= sizeof b)
        return ps_error_set(err, PS_ERR_PARSE, "%s: option %.*s: '%s' is not WIDTHxHEIGHT", cli->prog, n, opt, s);
    memcpy(a, s, (size_t)(x - s));
    a[x - s] = '\0';
    strcpy(b, x + 1);
    if (!ps_parse_int64(a, &wv) || !ps_parse_int64(b, &hv))
        return ps_error_set(err, PS_ERR_PARSE, "%s: option %.*s: '%s' is not WIDTHxHEIGHT", cli->prog, n, opt, s);
    if (wv < 1 || hv < 1 || wv > max_side || hv > max_side)
        return ps_error_set(err, PS_ERR_RANGE, "%s: option %.*s: each side must be in [1, %d]", cli->prog, n, opt,
                            max_side);
    *w = (int)wv;
    *h = (int)hv;
    return PS_OK;
}

ps_status ps_cli_unknown(const ps_cli *cli, ps_error *err)
{
    return ps_error_set(err, PS_ERR_PARSE, "%s: unknown option '%s' (see --help)", cli->prog, cli->argv[cli->i]);
}

int ps_cli_fail(const ps_error *err)
{
    fprintf(stderr, "%s\n", err->msg[0] ? err->msg : ps_status_name(err->status));
    /* Everything a user can cause (bad input, an unwritable path, a size that
     * does not fit in memory) is status 2, as the contract says. */
    return PS_EXIT_USAGE;
}

ps_status ps_cli_ascending(ps_cli *cli, double lo, double hi, double *out, int max, int *count, ps_error *err)
{
    int n;
    const char *opt, *s;
    ps_status st = fetch(cli, &n, &opt, &s, err);
    if (st != PS_OK)
        return st;
    *count = 0;
    for (const char *p = s;;) {
        char *end;
        double v = strtod(p, &end);
        if (end == p || !(v >= lo && v <= hi) || (*end != ',' && *end != '\0'))
            return ps_error_set(err, PS_ERR_PARSE, "%s: option %.*s: '%s' is not a comma list of numbers in [%g, %g]",
                                cli->prog, n, opt, s, lo, hi);
        if (*count == max)
            return ps_error_set(err, PS_ERR_PARSE, "%s: option %.*s: more than %d values", cli->prog, n, opt, max);
        if (*count > 0 && v <= out[*count - 1])
            return ps_error_set(err, PS_ERR_PARSE, "%s: option %.*s: values must ascend ('%s')", cli->prog, n, opt, s);
        out[(*count)++] = v;
        if (*end == '\0')
            return PS_OK;
        p = end + 1;
    }
}
