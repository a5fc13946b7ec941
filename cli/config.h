/* Per-station configuration: what a user should not retype at every run.
 * File format: `key = value` lines, `#` comments, optional `[station]` header. Default location
 * $XDG_CONFIG_HOME/csfcal/station.conf (or ~/.config/csfcal/station.conf); `--config` picks another.
 * Every numeric key has an allowed range; a bad value is refused with file, line and the range. */
#ifndef CSF_CONFIG_H
#define CSF_CONFIG_H

#include "core/csf_status.h"
#include "core/station.h"


/* Built-in defaults: 531 x 299 mm (24" 16:9), 1920 x 1080 px, 570 mm, 60 Hz, 8 bit. */
void csf_config_defaults(csf_config *c);

/* Loads path (or the default location when path is NULL; a missing default file is not an
 * error, a missing explicit one is). Values in the file override those already in c. */
csf_status csf_config_load(csf_config *c, const char *path, csf_error *err);

/* Parses one `key=value` (as from the command line or the file); `where` names it in errors. */
csf_status csf_config_set(csf_config *c, const char *key, const char *value, const char *where,
                          csf_error *err);

/* Default store path (XDG data dir), written into out. */
void csf_config_default_store_path(char *out, unsigned long out_len);

#endif
