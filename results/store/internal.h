/* Hooks into the store's two backends for tests and the benchmark: the SQLite backend's
 * connection (fault injection in tests, bulk loading in the benchmark) and the PostgreSQL
 * backend's fault hook. Not for use by the procedures: they go through results/store/store.h
 * only, so either backend can serve them. */
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
