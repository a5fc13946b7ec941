/* The store's schema migrations (results/store/migrations.c), one script per version step, shared
 * by the SQLite and PostgreSQL backends so both reach the same CSF_STORE_SCHEMA_VERSION. */
#ifndef CSF_STORE_MIGRATIONS_H
#define CSF_STORE_MIGRATIONS_H

#include "results/store/store.h"

/* SQL of each schema migration step: index v gives the script that takes version v to v + 1
 * (index 0 creates version 1). */
extern const char *const csf_store_migrations[CSF_STORE_SCHEMA_VERSION];
/* The PostgreSQL form of step v where it differs from the portable script (a REAL column is
 * DOUBLE PRECISION there); NULL where the same SQL runs on both. */
extern const char *const csf_store_migrations_pg[CSF_STORE_SCHEMA_VERSION];

#endif
