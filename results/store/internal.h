/* Internals of the SQLite store shared by results/store*.c, tests and the benchmark: direct access
 * to the connection (fault injection in tests, bulk loading in the benchmark). Not for use by
 * the procedures: they go through results/store/store.h only, so another backend can replace SQLite. */
#ifndef CSF_STORE_INTERNAL_H
#define CSF_STORE_INTERNAL_H

#include <sqlite3.h>

#include "results/store/store.h"

sqlite3 *csf_store_db(csf_store *s);

/* Fault injection for the tests (NULL in normal runs): the server backend calls it with the name
 * of a point where a dropped connection matters ("session_committed": a session's row was
 * committed, the station has not yet used it), so a test can stop or restart the server there
 * instead of racing it with sleeps. */
extern void (*csf_store_fault_hook)(const char *point);

#endif
