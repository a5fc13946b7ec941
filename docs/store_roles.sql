-- Least-privilege roles for a csfcal store on a PostgreSQL server (docs/store.md, "A lab's server").
-- Run once as the database owner, after the owner created the schema with one csfcal command
-- (`csfcal sessions init --store postgresql://owner@host/csfcal`):
--     psql "postgresql://owner@host/csfcal" -f docs/store_roles.sql
-- then give each station its own login in the group csf_station and each analyst one in
-- csf_analyst, with passwords kept in the client's ~/.pgpass (never on a command line):
--     CREATE ROLE booth1 LOGIN PASSWORD '...' IN ROLE csf_station;
--     CREATE ROLE alice LOGIN PASSWORD '...' IN ROLE csf_analyst;
-- Safe to run again.

SET client_min_messages = warning;

DO $$ BEGIN
  IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'csf_station') THEN
    CREATE ROLE csf_station NOLOGIN;
  END IF;
  IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'csf_analyst') THEN
    CREATE ROLE csf_analyst NOLOGIN;
  END IF;
END $$;

-- Nobody but the owner creates tables; both groups may use the schema.
REVOKE CREATE ON SCHEMA public FROM PUBLIC;
GRANT USAGE ON SCHEMA public TO csf_station, csf_analyst;

-- Analysts read everything and change nothing.
GRANT SELECT ON ALL TABLES IN SCHEMA public TO csf_analyst;

-- Stations read what they resume and list, add rows, and change only what a session changes:
-- its state, a display's current profile, an artifact completed by a second record, and the
-- thresholds of a session (replaced whole). No DROP, TRUNCATE, schema change or deletion of
-- measured rows (sessions, trials, readings, frame intervals).
GRANT SELECT ON ALL TABLES IN SCHEMA public TO csf_station;
GRANT INSERT ON sessions, trials, readings, frame_intervals, thresholds, artifacts, displays,
  observers, studies, participants, session_participants, display_profiles TO csf_station;
GRANT UPDATE (state, updated_utc) ON sessions TO csf_station;
GRANT UPDATE (profile_id) ON displays TO csf_station;
GRANT UPDATE (path, content, size_bytes) ON artifacts TO csf_station;
GRANT DELETE ON thresholds TO csf_station;
REVOKE ALL ON schema_version FROM csf_station;
GRANT SELECT ON schema_version TO csf_station;

-- Row-level security: a station changes its own sessions only (sessions.station is the login
-- that started the session), and adds rows only to them. Reading stays open to all stations:
-- the listing shows every session of the lab. The owner is not subject to these policies.
ALTER TABLE sessions ENABLE ROW LEVEL SECURITY;
DROP POLICY IF EXISTS csf_read ON sessions;
DROP POLICY IF EXISTS csf_start ON sessions;
DROP POLICY IF EXISTS csf_own ON sessions;
CREATE POLICY csf_read ON sessions FOR SELECT USING (true);
CREATE POLICY csf_start ON sessions FOR INSERT TO csf_station WITH CHECK (station = current_user);
CREATE POLICY csf_own ON sessions FOR UPDATE TO csf_station
  USING (station = current_user) WITH CHECK (station = current_user);

DO $$
DECLARE t text;
BEGIN
  FOREACH t IN ARRAY ARRAY['trials', 'readings', 'frame_intervals', 'thresholds', 'artifacts',
                           'session_participants'] LOOP
    EXECUTE format('ALTER TABLE %I ENABLE ROW LEVEL SECURITY', t);
    EXECUTE format('DROP POLICY IF EXISTS csf_read ON %I', t);
    EXECUTE format('DROP POLICY IF EXISTS csf_own ON %I', t);
    EXECUTE format('CREATE POLICY csf_read ON %I FOR SELECT USING (true)', t);
    EXECUTE format('CREATE POLICY csf_own ON %I FOR ALL TO csf_station USING (session_id IN '
                   '(SELECT id FROM sessions WHERE station = current_user)) WITH CHECK '
                   '(session_id IN (SELECT id FROM sessions WHERE station = current_user))', t);
  END LOOP;
END $$;
