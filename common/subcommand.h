/*
 * subcommand.h - command lines of the form PROGRAM [--help | --version] COMMAND [OPTIONS] [ARGS],
 * shared by poro (cli/poro.c) and poro-solve (cli/poro_solve.c). Header only, because poro-solve
 * links the solver library and nothing of common/.
 *
 * A program keeps a table of struct subcommand; subcommand_main() parses its own options with
 * getopt_long ("+": they end at the command's name), finds the command and runs it on an argv of
 * its own whose argv[0] is "PROGRAM NAME", so that getopt_long's messages name the command
 * ("poro submit: unrecognized option '--wiat'"), with optind reset for a fresh parse. Commands
 * parse their options with getopt_long too: "--opt value" and "--opt=value", options before or
 * after the arguments, "--" ends them. A bad command line exits SUBCOMMAND_USAGE (2); --help and
 * --version exit 0 and print on stdout.
 */
#ifndef PORO_SUBCOMMAND_H
#define PORO_SUBCOMMAND_H

#include <getopt.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define SUBCOMMAND_USAGE 2

struct subcommand {
	const char *name;
	const char *synopsis;     /* the usage after "PROGRAM ", lines after the first indented */
	const char *help;         /* what it does and its options, for PROGRAM NAME --help */
	int (*run)(const struct subcommand *self, int argc, char **argv); /* argv[0] is "PROGRAM NAME" */
};

/* PROGRAM NAME --help: the usage and the help on stdout; returns 0. */
static inline int subcommand_help(const char *program, const struct subcommand *cmd)
{
	printf("usage: %s %s\n\n%s", program, cmd->synopsis, cmd->help);
	return 0;
}

/* A refused command line: "PROGRAM NAME: <why>" (unless fmt is NULL: getopt_long has said it),
 * the usage and where to read more, on stderr; returns SUBCOMMAND_USAGE. */
static inline int subcommand_vusage_error(const char *program, const struct subcommand *cmd, const char *fmt,
					  va_list ap)
{
	if (fmt) {
		fprintf(stderr, "%s %s: ", program, cmd->name);
		vfprintf(stderr, fmt, ap);
		fputc('\n', stderr);
	}
	fprintf(stderr, "usage: %s %s\n(%s %s --help says more)\n", program, cmd->synopsis, program, cmd->name);
	return SUBCOMMAND_USAGE;
}

static inline int subcommand_usage_error(const char *program, const struct subcommand *cmd, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));
static inline int subcommand_usage_error(const char *program, const struct subcommand *cmd, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	int rc = subcommand_vusage_error(program, cmd, fmt, ap);
	va_end(ap);
	return rc;
}

/* Exactly want arguments are left after the options (what names them when missing): 0, or
 * SUBCOMMAND_USAGE after saying what is missing or extra. */
static inline int subcommand_positional(const char *program, const struct subcommand *cmd, int argc, char **argv,
					int want, const char *what)
{
	if (argc - optind < want)
		return subcommand_usage_error(program, cmd, "missing %s", what);
	if (argc - optind > want)
		return subcommand_usage_error(program, cmd, "unexpected argument '%s'", argv[optind + want]);
	return 0;
}

/* Every command's usage, one after the other, then "PROGRAM --help | --version". */
static inline void subcommand_list(FILE *f, const char *program, const struct subcommand *cmds, int count)
{
	for (int i = 0; i < count; i++)
		fprintf(f, "%s %s %s\n", i ? "      " : "usage:", program, cmds[i].synopsis);
	fprintf(f, "       %s --help | --version    (%s COMMAND --help for one command)\n", program, program);
}

/* Runs the command line: --help calls help(), --version prints "PROGRAM VERSION", a command runs
 * on its own argv; anything else lists the usage on stderr. Returns the exit status. */
static inline int subcommand_main(const char *program, const char *version, const struct subcommand *cmds, int count,
				  int (*help)(void), int argc, char **argv)
{
	static const struct option opts[] = {
		{ "help", no_argument, NULL, 'h' }, { "version", no_argument, NULL, 'V' }, { NULL, 0, NULL, 0 }
	};
	int c = getopt_long(argc, argv, "+hV", opts, NULL);
	if (c == 'h')
		return help();
	if (c == 'V') {
		printf("%s %s\n", program, version);
		return 0;
	}
	const struct subcommand *cmd = NULL;
	for (int i = 0; c == -1 && optind < argc && i < count && !cmd; i++)
		if (!strcmp(argv[optind], cmds[i].name))
			cmd = &cmds[i];
	if (!cmd) {
		if (c == -1 && optind < argc)
			fprintf(stderr, "%s: unknown command '%s'\n", program, argv[optind]);
		subcommand_list(stderr, program, cmds, count);
		return SUBCOMMAND_USAGE;
	}
	char name[64];
	snprintf(name, sizeof name, "%s %s", program, cmd->name);
	char **cargv = argv + optind;
	int cargc = argc - optind;
	cargv[0] = name;
	optind = 0;   /* glibc: start afresh on the command's argv */
	return cmd->run(cmd, cargc, cargv);
}

#endif
