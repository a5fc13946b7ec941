/* The PostgreSQL form of the store's schema (results/store/pg_schema.c). */
#ifndef CSF_STORE_PG_SCHEMA_H
#define CSF_STORE_PG_SCHEMA_H

/* Creates every table of schema version 5 in an empty database (one transaction). */
extern const char *const csf_store_pg_schema_v5;

#endif
