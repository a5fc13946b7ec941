/* Credentials and roles.
 * Always: a password in a store location, however libpq would read it (user:pw@, pass%77ord=,
 * %70assword=, after a '#', sslpassword), is refused without being repeated and is absent from
 * the one form in which csfcal shows a location (csf_store_redact).
 * On a server (CSF_TEST_BACKEND=postgresql, under tests/store/pg_run.sh): the roles of
 * docs/store_roles.sql, with passwords only in a libpq password file (PGPASSFILE):
 * a station starts sessions and adds trials to its own, cannot change or add to another
 * station's, cannot delete measured rows or change the schema; an analyst reads and cannot
 * write; and no password reaches the store's rows or a message. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "results/store/store.h"
#include "store_test_util.h"
#include "tests/check.h"

static void check_redact(const char *in, const char *want)
{
    char out[512];
    csf_store_redact(in, out, sizeof out);
    CHECK_MSG(!strcmp(out, want), "redact(%s) = %s, want %s", in, out, want);
    CHECK_INT_EQ(csf_store_has_password(in), strcmp(in, want) != 0);
}

/* The location is refused, and neither the message nor the redacted form holds secret. */
static void check_refused(const char *in, const char *secret)
{
    csf_error err;
    csf_store *s = NULL;
    CHECK_MSG(csf_store_has_password(in), "password not seen in %s", in);
    CHECK_INT_EQ(csf_store_check_location(in, "--store", &err), CSF_E_INVALID_ARG);
    CHECK_MSG(!strstr(err.msg, secret), "check message shows the secret: %s", err.msg);
    CHECK_STR_CONTAINS(err.msg, "pgpass");
    CHECK_INT_EQ(csf_store_open(in, &s, &err), CSF_E_INVALID_ARG);
    CHECK(s == NULL);
    CHECK_MSG(!strstr(err.msg, secret), "open message shows the secret: %s", err.msg);
    char out[512];
    csf_store_redact(in, out, sizeof out);
    CHECK_MSG(!strstr(out, secret), "redact(%s) = %s", in, out);
    CHECK(!csf_store_has_password(out));
}

static void test_redact(void)
{
    /* A password is found as libpq reads it, however it is spelled; the location is then
     * shown as the key=value pairs libpq read, without it. */
    check_redact("postgresql://bob:s3cret@db.lab:5433/csf?sslmode=require",
                 "user=bob dbname=csf host=db.lab port=5433 sslmode=require");
    check_redact("postgres://bob:p%40ss@db/csf", "user=bob dbname=csf host=db");
    check_redact("postgresql://db/csf?pass%77ord=s3cret", "dbname=csf host=db");
    check_redact("postgresql://db/csf?%70assword=s3cret", "dbname=csf host=db");
    check_redact("postgresql://db/csf?application_name=x#&password=s3cret",
                 "dbname=csf host=db application_name=x#");
    check_redact("postgresql://db/csf?sslpassword=s3cret", "dbname=csf host=db");
    check_redact("service=lab password=s3cret sslmode=require", "service=lab sslmode=require");
    /* Values are quoted as libpq reads them back; a backslash is shown escaped, as every byte
     * that could be taken for an escape. */
    check_redact("service=lab password='s3 cret' user='b o\\'b'", "service=lab user='b o\\x5c'b'");
    check_redact("service=lab'x password=s3cret", "service='lab\\x5c'x'");
    /* Without a secret the location is shown as given. */
    check_redact("postgresql:///csf?host=/run/pg&user=booth1", "postgresql:///csf?host=/run/pg&user=booth1");
    char out[64];
    csf_store_redact("service=lab  host=h\tport=5", out, sizeof out); /* a tab is escaped */
    CHECK_MSG(!strcmp(out, "service=lab  host=h\\x09port=5"), "tab: %s", out);
    check_redact("/data/lab/csfcal.sqlite", "/data/lab/csfcal.sqlite");
    check_redact("/data/p:w@x/csfcal.sqlite", "/data/p:w@x/csfcal.sqlite"); /* a file path */
    /* What libpq cannot read is not shown at all: it may be a secret typed in the wrong place. */
    csf_store_redact("postgresql://db/csf?s3cret", out, sizeof out);
    CHECK_MSG(!strcmp(out, "(a connection string libpq cannot read; not shown)"), "unread: %s", out);

    check_refused("postgresql://bob:s3cret@127.0.0.1:1/csf", "s3cret");
    check_refused("postgresql://127.0.0.1:1/csf?pass%77ord=s3cret", "s3cret");
    check_refused("postgresql://127.0.0.1:1/csf?%70assword=s3cret", "s3cret");
    check_refused("postgresql://127.0.0.1:1/csf?application_name=x#&password=s3cret", "s3cret");
    check_refused("service=lab password=s3cret", "s3cret");
    check_refused("service=lab sslpassword=s3cret", "s3cret");
    csf_error err;
    /* Not a server location to csfcal (a file name), but one libpq reads a password from. */
    CHECK_INT_EQ(csf_store_check_location("host=db password=s3cret", "--store", &err), CSF_E_INVALID_ARG);
    CHECK(!strstr(err.msg, "s3cret"));
    CHECK_INT_EQ(csf_store_check_location("/data/a=b/csfcal.sqlite", "--store", &err), CSF_OK);
    CHECK_INT_EQ(csf_store_check_location("postgresql://db/csf?s3cret", "--to", &err), CSF_E_INVALID_ARG);
    CHECK(!strstr(err.msg, "s3cret"));
    CHECK_STR_CONTAINS(err.msg, "libpq cannot read");
}

/* Runs a file of SQL (the roles script) as the test server's superuser. */
static int admin_script(const char *db, const char *file)
{
    FILE *f = fopen(file, "rb");
    if (!f) return -1;
    static char sql[65536];
    size_t n = fread(sql, 1, sizeof sql - 1, f);
    fclose(f);
    sql[n] = '\0';
    return test_pg_admin(db, sql);
}

static void loc_as(const char *db, const char *user, char *out, size_t cap)
{
    snprintf(out, cap, "postgresql:///%s?host=%s&user=%s", db, getenv("CSF_TEST_PG_DIR"), user);
}

/* A statement run directly as user (what a station role could try by hand); 0 when allowed. */
static int try_as(const char *db, const char *user, const char *sql)
{
    char uri[1024];
    loc_as(db, user, uri, sizeof uri);
    PGconn *c = PQconnectdb(uri);
    int ok = PQstatus(c) == CONNECTION_OK;
    if (ok) {
        PGresult *r = PQexec(c, sql);
        ok = PQresultStatus(r) == PGRES_COMMAND_OK || PQresultStatus(r) == PGRES_TUPLES_OK;
        PQclear(r);
    }
    PQfinish(c);
    return ok ? 0 : -1;
}

static void test_roles(const char *roles_sql)
{
    char owner[1024], db[64];
    CHECK_INT_EQ(test_store_location("", "", owner, sizeof owner), 0);
    sscanf(owner, "postgresql:///%63[^?]", db);
    csf_error err;
    csf_store *s = NULL;
    CHECK_INT_EQ(csf_store_open(owner, &s, &err), CSF_OK); /* the owner makes the schema */
    csf_store_close(s);
    CHECK_INT_EQ(admin_script(db, roles_sql), 0);
    CHECK_INT_EQ(admin_script(db, roles_sql), 0); /* safe to run again */
    test_pg_admin(db, "DO $$ BEGIN IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'booth1')"
                      " THEN CREATE ROLE booth1 LOGIN PASSWORD 'pw-booth-one' IN ROLE csf_station;"
                      " CREATE ROLE booth2 LOGIN PASSWORD 'pw-booth-two' IN ROLE csf_station;"
                      " CREATE ROLE alice LOGIN PASSWORD 'pw-alice' IN ROLE csf_analyst; END IF; END $$");
    char pass[600];
    snprintf(pass, sizeof pass, "%s/pgpass", getenv("CSF_TEST_PG_DIR"));
    FILE *f = fopen(pass, "w");
    if (!f) return;
    fprintf(f, "*:*:*:booth1:pw-booth-one\n*:*:*:booth2:pw-booth-two\n*:*:*:alice:pw-alice\n");
    fclose(f);
    chmod(pass, 0600); /* libpq ignores a password file others can read */
    setenv("PGPASSFILE", pass, 1);

    char b1[1024], b2[1024], an[1024];
    loc_as(db, "booth1", b1, sizeof b1);
    loc_as(db, "booth2", b2, sizeof b2);
    loc_as(db, "alice", an, sizeof an);
    csf_store *s1 = NULL, *s2 = NULL, *sa = NULL;
    CHECK_INT_EQ(csf_store_open(b1, &s1, &err), CSF_OK);
    CHECK_INT_EQ(csf_store_open(b2, &s2, &err), CSF_OK);
    if (!s1 || !s2) {
        fprintf(stderr, "station open: %s\n", err.msg);
        return;
    }
    int64_t sid1 = 0, sid2 = 0;
    CHECK_INT_EQ(csf_store_begin_session(s1, CSF_SESSION_OBSERVER, "p1", "booth-lcd", NULL, 1, &sid1, &err),
                 CSF_OK);
    CHECK_INT_EQ(csf_store_begin_session(s2, CSF_SESSION_OBSERVER, "p2", "booth-lcd", NULL, 2, &sid2, &err),
                 CSF_OK);
    for (int i = 0; i < 5; i++) {
        csf_trial t = make_trial(sid1, i, 1);
        CHECK_INT_EQ(csf_store_add_trial(s1, &t, &err), CSF_OK);
    }
    /* booth2 cannot add to booth1's session, nor change it once booth1 let go of it. */
    csf_trial foreign = make_trial(sid1, 5, 1);
    CHECK(csf_store_add_trial(s2, &foreign, &err) != CSF_OK);
    CHECK_STR_CONTAINS(err.msg, "permission denied");
    CHECK_INT_EQ(csf_store_set_session_state(s1, sid1, CSF_SESSION_PAUSED, &err), CSF_OK);
    CHECK(csf_store_set_session_state(s2, sid1, CSF_SESSION_ABORTED, &err) != CSF_OK);
    CHECK_INT_EQ(csf_store_set_session_state(s2, sid2, CSF_SESSION_FINISHED, &err), CSF_OK);
    /* Stations list every session of the lab. */
    csf_session_info *list = NULL;
    size_t n = 0;
    CHECK_INT_EQ(csf_store_list_sessions(s2, &list, &n, &err), CSF_OK);
    CHECK_INT_EQ(n, 2);
    csf_session_list_free(list, n);
    csf_store_close(s1);
    csf_store_close(s2);
    /* No deleting measured rows, no schema changes, no other role's work undone. */
    CHECK(try_as(db, "booth1", "DELETE FROM trials") != 0);
    CHECK(try_as(db, "booth1", "DROP TABLE trials") != 0);
    CHECK(try_as(db, "booth1", "CREATE TABLE x (a INTEGER)") != 0);
    CHECK(try_as(db, "booth1", "UPDATE trials SET response = 0") != 0);
    CHECK(try_as(db, "booth1", "UPDATE sessions SET seed = 0") != 0);
    CHECK(try_as(db, "booth1", "SELECT COUNT(*) FROM trials") == 0);

    /* The analyst reads everything and writes nothing, through csfcal or by hand. */
    CHECK_INT_EQ(csf_store_open_readonly(an, &sa, &err), CSF_OK);
    if (sa) {
        csf_trial *t = NULL;
        size_t nt = 0;
        CHECK_INT_EQ(csf_store_get_trials(sa, sid1, &t, &nt, &err), CSF_OK);
        CHECK_INT_EQ(nt, 5);
        free(t);
        csf_store_close(sa);
    }
    sa = NULL;
    CHECK_INT_EQ(csf_store_open(an, &sa, &err), CSF_OK);
    if (sa) {
        int64_t x = 0;
        CHECK_INT_EQ(csf_store_begin_session(sa, CSF_SESSION_OBSERVER, "a", "d", NULL, 1, &x, &err),
                     CSF_E_STORE);
        CHECK_STR_CONTAINS(err.msg, "permission denied");
        CHECK(strstr(err.msg, "pw-alice") == NULL);
        csf_store_close(sa);
    }
    CHECK(try_as(db, "alice", "INSERT INTO observers (name, created_utc) VALUES ('x', 'y')") != 0);
    CHECK(try_as(db, "alice", "SELECT COUNT(*) FROM sessions") == 0);

    /* A wrong password: refused, and the message does not show it. */
    f = fopen(pass, "w");
    if (f) {
        fprintf(f, "*:*:*:booth1:not-the-password\n");
        fclose(f);
    }
    CHECK_INT_EQ(csf_store_open(b1, &s1, &err), CSF_E_STORE);
    CHECK_STR_CONTAINS(err.msg, "password authentication failed");
    CHECK(strstr(err.msg, "not-the-password") == NULL);
    unsetenv("PGPASSFILE");
    /* Nothing the stations stored holds a password. */
    CHECK_INT_EQ(test_query_int(NULL, owner, "SELECT COUNT(*) FROM sessions WHERE settings_json"
                                             " LIKE '%pw-%' OR observer LIKE '%pw-%'"), 0);
    CHECK_INT_EQ(test_query_int(NULL, owner, "SELECT COUNT(*) FROM sessions WHERE station = 'booth1'"), 1);
}

int main(int argc, char **argv)
{
    test_redact();
    if (test_pg()) {
        test_pg_require();
        if (argc < 2) {
            fprintf(stderr, "usage: test_store_security ROLES.sql\n");
            return 2;
        }
        test_roles(argv[1]);
    }
    return CHECK_RESULT();
}
