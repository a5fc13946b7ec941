/* The store's schema migrations, shared by both backends: results/store/sqlite.c runs every step
 * on a local file, results/store/pg.c the steps after the version its own schema script
 * (results/store/pg_schema.c) creates. */
#include "results/store/migrations.h"

/* ---- schema ------------------------------------------------------------------------------
 * Portable types only (INTEGER, REAL, TEXT, BLOB); booleans are INTEGER 0/1; times are ISO 8601
 * text (created/updated) or Unix seconds as REAL (per-row stored_s). NaN is stored as NULL. */
const char *const csf_store_migrations[CSF_STORE_SCHEMA_VERSION] = {
    /* -> v1: sessions, readings, trials, thresholds, displays, observers */
    "CREATE TABLE schema_version (version INTEGER NOT NULL);"
    "INSERT INTO schema_version (version) VALUES (0);"
    "CREATE TABLE displays (id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE, profile_id TEXT,"
    "  created_utc TEXT NOT NULL);"
    "CREATE TABLE observers (id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE,"
    "  created_utc TEXT NOT NULL);"
    "CREATE TABLE sessions (id INTEGER PRIMARY KEY, kind TEXT NOT NULL, state TEXT NOT NULL,"
    "  observer TEXT NOT NULL DEFAULT '', display TEXT NOT NULL DEFAULT '',"
    "  settings_json TEXT NOT NULL, seed INTEGER NOT NULL, tool_version TEXT NOT NULL,"
    "  created_utc TEXT NOT NULL, updated_utc TEXT NOT NULL);"
    "CREATE TABLE readings (session_id INTEGER NOT NULL REFERENCES sessions(id),"
    "  seq INTEGER NOT NULL, channel TEXT NOT NULL, drive01 REAL NOT NULL, lum_cdm2 REAL,"
    "  x REAL, y REAL, z REAL, t_s REAL NOT NULL, status TEXT NOT NULL,"
    "  PRIMARY KEY (session_id, seq));"
    "CREATE TABLE trials (session_id INTEGER NOT NULL REFERENCES sessions(id),"
    "  seq INTEGER NOT NULL, method TEXT NOT NULL, freq_cpd REAL NOT NULL, ecc_deg REAL NOT NULL,"
    "  polar_deg REAL NOT NULL, orientation_deg REAL NOT NULL, sigma_deg REAL NOT NULL,"
    "  mean_lum_cdm2 REAL NOT NULL, is_catch INTEGER NOT NULL, is_practice INTEGER NOT NULL,"
    "  contrast_requested REAL NOT NULL, contrast_shown_mean REAL, contrast_shown_max REAL,"
    "  frames_planned INTEGER NOT NULL, frames_shown INTEGER NOT NULL,"
    "  frames_missed INTEGER NOT NULL, signal_interval INTEGER NOT NULL,"
    "  response INTEGER NOT NULL, rt_s REAL, valid INTEGER NOT NULL,"
    "  PRIMARY KEY (session_id, seq));"
    "CREATE TABLE thresholds (session_id INTEGER NOT NULL REFERENCES sessions(id),"
    "  freq_cpd REAL NOT NULL, ecc_deg REAL NOT NULL, lum_cdm2 REAL NOT NULL, threshold REAL,"
    "  stderr_log10 REAL, n_trials INTEGER NOT NULL);",

    /* -> v2: moving stimuli and click responses in trials, problem flags, per-row store time,
     * frame intervals, artifacts (tables, profiles, plots with their bytes). */
    "ALTER TABLE trials ADD COLUMN velocity_dps REAL NOT NULL DEFAULT 0;"
    "ALTER TABLE trials ADD COLUMN click_x_deg REAL;"
    "ALTER TABLE trials ADD COLUMN click_y_deg REAL;"
    "ALTER TABLE trials ADD COLUMN flags TEXT NOT NULL DEFAULT '';"
    "ALTER TABLE trials ADD COLUMN stored_s REAL;"
    "ALTER TABLE readings ADD COLUMN stored_s REAL;"
    "ALTER TABLE thresholds ADD COLUMN velocity_dps REAL NOT NULL DEFAULT 0;"
    "CREATE TABLE frame_intervals (session_id INTEGER NOT NULL REFERENCES sessions(id),"
    "  trial_seq INTEGER NOT NULL, idx INTEGER NOT NULL, interval_s REAL NOT NULL,"
    "  PRIMARY KEY (session_id, trial_seq, idx));"
    "CREATE TABLE artifacts (id INTEGER PRIMARY KEY,"
    "  session_id INTEGER NOT NULL REFERENCES sessions(id), kind TEXT NOT NULL,"
    "  path TEXT NOT NULL, size_bytes INTEGER NOT NULL, content BLOB,"
    "  created_utc TEXT NOT NULL);",

    /* -> v3: studies and participants (2AFC user studies), display profiles per display. */
    "CREATE TABLE studies (id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE,"
    "  design_json TEXT NOT NULL, created_utc TEXT NOT NULL);"
    "CREATE TABLE participants (id INTEGER PRIMARY KEY,"
    "  study_id INTEGER NOT NULL REFERENCES studies(id), code TEXT NOT NULL,"
    "  created_utc TEXT NOT NULL, UNIQUE (study_id, code));"
    "CREATE TABLE session_participants (session_id INTEGER PRIMARY KEY REFERENCES sessions(id),"
    "  participant_id INTEGER NOT NULL REFERENCES participants(id));"
    "CREATE TABLE display_profiles (id INTEGER PRIMARY KEY,"
    "  display_id INTEGER NOT NULL REFERENCES displays(id), profile_id TEXT NOT NULL,"
    "  session_id INTEGER REFERENCES sessions(id), created_utc TEXT NOT NULL);"
    "CREATE INDEX artifacts_session ON artifacts (session_id, kind);"
    "CREATE INDEX thresholds_session ON thresholds (session_id);",

    /* -> v4: forced-choice layout per trial: 2 = two intervals, 4 = four places shown at once
     * (spatial 4AFC), 0 = not forced choice. Every forced-choice trial stored before had two
     * intervals (signal_interval 1 or 2). */
    "ALTER TABLE trials ADD COLUMN n_alternatives INTEGER NOT NULL DEFAULT 0;"
    "UPDATE trials SET n_alternatives = 2 WHERE signal_interval > 0;",

    /* -> v5: observer sessions name the display they ran on and, apart, the profile they used
     * (before, the profile id stood in the display column and a display row with no profile was
     * made for it); a profile file is one artifact row, not a row with the bytes and another
     * with the path; units in column names; one threshold per cell; CHECKs on enumerations.
     * Tables whose columns change are rebuilt (SQLite cannot add a CHECK to a table); the
     * migration runs with foreign keys off, as SQLite's documented rebuild procedure requires. */
    "CREATE TABLE sessions_v5 (id INTEGER PRIMARY KEY,"
    "  kind TEXT NOT NULL CHECK (kind IN ('display', 'observer', 'study')),"
    "  state TEXT NOT NULL CHECK (state IN ('running', 'paused', 'finished', 'aborted')),"
    "  observer TEXT NOT NULL DEFAULT '', display TEXT NOT NULL DEFAULT '', profile_id TEXT,"
    "  settings_json TEXT NOT NULL, seed INTEGER NOT NULL, tool_version TEXT NOT NULL,"
    "  created_utc TEXT NOT NULL, updated_utc TEXT NOT NULL);"
    /* A profile id as display: the default profile's id, an id with a recorded history, or the
     * "<display>-<yyyymmdd|undated>-<8 hex digits>" form every measured profile's id has. */
    "INSERT INTO sessions_v5 (id, kind, state, observer, display, profile_id, settings_json, seed,"
    "  tool_version, created_utc, updated_utc)"
    "  SELECT id, kind, state, observer, display,"
    "  CASE WHEN kind = 'observer' AND (display = 'default-gamma2.2-100cdm2'"
    "    OR display IN (SELECT profile_id FROM display_profiles)"
    "    OR display GLOB '*-[0-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9]-"
    "[0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f]'"
    "    OR display GLOB '*-undated-[0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f]')"
    "  THEN display END, settings_json, seed, tool_version, created_utc, updated_utc FROM sessions;"
    "DROP TABLE sessions;"
    "ALTER TABLE sessions_v5 RENAME TO sessions;"
    /* The real display: the one the profile was measured on when this store measured it; the
     * default profile's display is 'default'; otherwise unknown (''), the profile id is kept. */
    "UPDATE sessions SET display = COALESCE((SELECT d.name FROM display_profiles p"
    "  JOIN displays d ON d.id = p.display_id WHERE p.profile_id = sessions.profile_id"
    "  ORDER BY p.id DESC LIMIT 1),"
    "  CASE WHEN profile_id = 'default-gamma2.2-100cdm2' THEN 'default' ELSE '' END)"
    "  WHERE profile_id IS NOT NULL;"
    "DELETE FROM displays WHERE profile_id IS NULL"
    "  AND name IN (SELECT profile_id FROM sessions WHERE profile_id IS NOT NULL)"
    "  AND name NOT IN (SELECT display FROM sessions)"
    "  AND id NOT IN (SELECT display_id FROM display_profiles);"
    "INSERT INTO displays (name, profile_id, created_utc) SELECT display, NULL, MIN(created_utc)"
    "  FROM sessions WHERE display <> '' AND display NOT IN (SELECT name FROM displays)"
    "  GROUP BY display;"
    "INSERT INTO display_profiles (display_id, profile_id, session_id, created_utc)"
    "  SELECT d.id, s.profile_id, NULL, MIN(s.created_utc) FROM sessions s"
    "  JOIN displays d ON d.name = s.display WHERE s.profile_id IS NOT NULL AND NOT EXISTS"
    "  (SELECT 1 FROM display_profiles p WHERE p.display_id = d.id AND p.profile_id = s.profile_id)"
    "  GROUP BY d.id, s.profile_id;"
    "UPDATE displays SET profile_id = (SELECT p.profile_id FROM display_profiles p"
    "  WHERE p.display_id = displays.id ORDER BY p.id DESC LIMIT 1) WHERE profile_id IS NULL;"

    "CREATE TABLE readings_v5 (session_id INTEGER NOT NULL REFERENCES sessions(id),"
    "  seq INTEGER NOT NULL CHECK (seq >= 0),"
    "  channel TEXT NOT NULL CHECK (channel IN ('dark', 'white', 'grey', 'r', 'g', 'b')),"
    "  drive01 REAL NOT NULL CHECK (drive01 >= 0 AND drive01 <= 1), lum_cdm2 REAL,"
    "  X_cdm2 REAL, Y_cdm2 REAL, Z_cdm2 REAL, t_s REAL NOT NULL,"
    "  status TEXT NOT NULL CHECK (status IN ('ok', 'too_dark', 'saturated', 'timeout', 'error')),"
    "  stored_s REAL, PRIMARY KEY (session_id, seq));"
    "INSERT INTO readings_v5 SELECT session_id, seq, channel, drive01, lum_cdm2, x, y, z, t_s,"
    "  status, stored_s FROM readings;"
    "DROP TABLE readings;"
    "ALTER TABLE readings_v5 RENAME TO readings;"

    "CREATE TABLE trials_v5 (session_id INTEGER NOT NULL REFERENCES sessions(id),"
    "  seq INTEGER NOT NULL CHECK (seq >= 0), method TEXT NOT NULL, freq_cpd REAL NOT NULL,"
    "  ecc_deg REAL NOT NULL, polar_deg REAL NOT NULL, orientation_deg REAL NOT NULL,"
    "  sigma_deg REAL NOT NULL, mean_lum_cdm2 REAL NOT NULL,"
    "  is_catch INTEGER NOT NULL CHECK (is_catch IN (0, 1)),"
    "  is_practice INTEGER NOT NULL CHECK (is_practice IN (0, 1)),"
    "  contrast_requested REAL NOT NULL, contrast_shown_mean REAL, contrast_shown_max REAL,"
    "  frames_planned INTEGER NOT NULL, frames_shown INTEGER NOT NULL,"
    "  frames_missed INTEGER NOT NULL, signal_interval INTEGER NOT NULL,"
    "  response INTEGER NOT NULL, rt_s REAL, valid INTEGER NOT NULL CHECK (valid IN (0, 1)),"
    "  velocity_dps REAL NOT NULL DEFAULT 0, click_x_deg REAL, click_y_deg REAL,"
    "  flags TEXT NOT NULL DEFAULT '', stored_s REAL,"
    "  n_alternatives INTEGER NOT NULL DEFAULT 0"
    "  CHECK (n_alternatives = 0 OR n_alternatives BETWEEN 2 AND 16),"
    "  PRIMARY KEY (session_id, seq));"
    "INSERT INTO trials_v5 SELECT session_id, seq, method, freq_cpd, ecc_deg, polar_deg,"
    "  orientation_deg, sigma_deg, mean_lum_cdm2, is_catch, is_practice, contrast_requested,"
    "  contrast_shown_mean, contrast_shown_max, frames_planned, frames_shown, frames_missed,"
    "  signal_interval, response, rt_s, valid, velocity_dps, click_x_deg, click_y_deg, flags,"
    "  stored_s, n_alternatives FROM trials;"
    "DROP TABLE trials;"
    "ALTER TABLE trials_v5 RENAME TO trials;"

    /* put_thresholds always replaced a session's rows whole, so a duplicate cell can only come
     * from a caller passing one twice: the last row stored wins, as a reader saw it last. */
    "CREATE TABLE thresholds_v5 (session_id INTEGER NOT NULL REFERENCES sessions(id),"
    "  freq_cpd REAL NOT NULL, ecc_deg REAL NOT NULL, velocity_dps REAL NOT NULL DEFAULT 0,"
    "  lum_cdm2 REAL NOT NULL, threshold_michelson REAL, stderr_log10 REAL,"
    "  n_trials INTEGER NOT NULL,"
    "  UNIQUE (session_id, lum_cdm2, velocity_dps, ecc_deg, freq_cpd));"
    "INSERT INTO thresholds_v5 SELECT session_id, freq_cpd, ecc_deg, velocity_dps, lum_cdm2,"
    "  threshold, stderr_log10, n_trials FROM thresholds t WHERE rowid = (SELECT MAX(rowid)"
    "  FROM thresholds u WHERE u.session_id = t.session_id AND u.lum_cdm2 = t.lum_cdm2"
    "  AND u.velocity_dps = t.velocity_dps AND u.ecc_deg = t.ecc_deg AND u.freq_cpd = t.freq_cpd);"
    "DROP TABLE thresholds;"
    "ALTER TABLE thresholds_v5 RENAME TO thresholds;"

    /* One profile file, one row: the row with the bytes takes the path of the path-only row. */
    "UPDATE artifacts SET path = (SELECT b.path FROM artifacts b WHERE b.session_id ="
    "  artifacts.session_id AND b.kind = artifacts.kind AND b.content IS NULL AND b.path <> ''"
    "  ORDER BY b.id LIMIT 1) WHERE path = '' AND content IS NOT NULL AND EXISTS (SELECT 1"
    "  FROM artifacts b WHERE b.session_id = artifacts.session_id AND b.kind = artifacts.kind"
    "  AND b.content IS NULL AND b.path <> '');"
    "DELETE FROM artifacts WHERE content IS NULL AND path <> '' AND EXISTS (SELECT 1 FROM"
    "  artifacts a WHERE a.session_id = artifacts.session_id AND a.kind = artifacts.kind"
    "  AND a.content IS NOT NULL AND a.path = artifacts.path);",

    /* -> v6 (portable: run on SQLite and PostgreSQL alike): a session has a uuid, so a copy of
     * it in another store (csfcal sessions push, a station's spool) is recognised and never
     * doubled; and the station (server login) that started it, which the server's row-level
     * policies use to let a station change only its own sessions. Older sessions get their
     * uuid when first pushed. */
    "ALTER TABLE sessions ADD COLUMN uuid TEXT;"
    "ALTER TABLE sessions ADD COLUMN station TEXT NOT NULL DEFAULT '';"
    "CREATE UNIQUE INDEX sessions_uuid ON sessions (uuid);",

    /* -> v7: the participant's time in a session (person_s, seconds, the runs of a resumed
     * session added up), NULL where unknown: every session stored before. The server's form
     * (below) differs only in the type. */
    "ALTER TABLE sessions ADD COLUMN person_s REAL CHECK (person_s IS NULL OR person_s >= 0);",

    /* -> v8: when each trial was shown (onset_s, seconds on the session's clock, the runs of a
     * resumed session following each other), NULL where not recorded: every trial stored before
     * and trials of procedures that keep no onset. The server's form differs only in the type. */
    "ALTER TABLE trials ADD COLUMN onset_s REAL CHECK (onset_s IS NULL OR onset_s >= 0);",
};

/* A step whose server form differs: PostgreSQL's REAL is 4 bytes and would round every value,
 * so a REAL column is DOUBLE PRECISION there (as in results/store/pg_schema.c). */
static const char pg_v7_person_s[] =
    "ALTER TABLE sessions ADD COLUMN person_s DOUBLE PRECISION CHECK (person_s IS NULL OR person_s >= 0);";
static const char pg_v8_onset_s[] =
    "ALTER TABLE trials ADD COLUMN onset_s DOUBLE PRECISION CHECK (onset_s IS NULL OR onset_s >= 0);";
const char *const csf_store_migrations_pg[CSF_STORE_SCHEMA_VERSION] = {
    [6] = pg_v7_person_s,
    [7] = pg_v8_onset_s,
};
