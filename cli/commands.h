/* Subcommands of the csfcal executable. Each receives argv starting at its own name
 * (argv[0] = "lut", ...) and returns the process exit status. */
#ifndef CSF_COMMANDS_H
#define CSF_COMMANDS_H

int csf_cmd_lut(int argc, char **argv);
int csf_cmd_display(int argc, char **argv);
int csf_cmd_observer(int argc, char **argv);
int csf_cmd_study(int argc, char **argv);
int csf_cmd_sessions(int argc, char **argv);
int csf_cmd_report(int argc, char **argv);
int csf_cmd_devices(int argc, char **argv);
int csf_cmd_stimulus(int argc, char **argv);

#endif
