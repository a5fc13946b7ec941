-- Least-privilege roles for a csfcal store on a PostgreSQL server (docs/store.md, "A lab's server").
-- Run by a superuser (it creates roles and restricts functions of pg_catalog), once the database
-- owner has created the schema with one csfcal command
-- (`csfcal sessions init --store postgresql://csfcal_owner@host/csfcal`):
--     sudo -u postgres psql -d csfcal -f docs/store_roles.sql
-- The database owner needs no CREATEROLE for this (on PostgreSQL 15 CREATEROLE would let it grant
-- itself pg_execute_server_program). Then give each station its own login in the group
-- csf_station and each analyst one in csf_analyst, with passwords kept in the client's
-- ~/.pgpass (never on a command line):
--     CREATE ROLE booth1 LOGIN PASSWORD '...' IN ROLE csf_station;
--     CREATE ROLE alice LOGIN PASSWORD '...' IN ROLE csf_analyst;
-- Safe to run again; run it again after a csfcal upgrade, once csfcal has migrated the store
-- (csfcal sessions init: the rules name the current schema's columns, such as v7's person_s;
-- they are not part of the schema migrations: a store with no station roles needs none of them).

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
-- its state and person time, a display's current profile, an artifact completed by a second record, and the
-- thresholds of a session (replaced whole). No DROP, TRUNCATE, schema change or deletion of
-- measured rows (sessions, trials, readings, frame intervals).
GRANT SELECT ON ALL TABLES IN SCHEMA public TO csf_station;
GRANT INSERT ON sessions, trials, readings, frame_intervals, thresholds, artifacts, displays,
  observers, studies, participants, session_participants, display_profiles TO csf_station;
GRANT UPDATE (state, updated_utc, person_s) ON sessions TO csf_station;
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

-- Rows without a session of their own. A participant is added by the station whose study session
-- it belongs to, while that session has none yet (csfcal adds it right after starting the
-- session, which carries the participant's code as its observer): no station can take a
-- participant code without running a session for it. A display
-- profile history row names a session of the station itself, or none (a profile only used).
ALTER TABLE participants ENABLE ROW LEVEL SECURITY;
DROP POLICY IF EXISTS csf_read ON participants;
DROP POLICY IF EXISTS csf_add ON participants;
CREATE POLICY csf_read ON participants FOR SELECT USING (true);
CREATE POLICY csf_add ON participants FOR INSERT TO csf_station WITH CHECK (EXISTS (
  SELECT 1 FROM sessions s WHERE s.station = current_user AND s.kind = 'study'
    AND s.observer = participants.code AND s.state IN ('running', 'paused')
    AND NOT EXISTS (SELECT 1 FROM session_participants sp WHERE sp.session_id = s.id)));

ALTER TABLE display_profiles ENABLE ROW LEVEL SECURITY;
DROP POLICY IF EXISTS csf_read ON display_profiles;
DROP POLICY IF EXISTS csf_own ON display_profiles;
CREATE POLICY csf_read ON display_profiles FOR SELECT USING (true);
CREATE POLICY csf_own ON display_profiles FOR INSERT TO csf_station WITH CHECK (session_id IS NULL
  OR session_id IN (SELECT id FROM sessions WHERE station = current_user));

-- Advisory locks are csfcal's session claims and schema lock. Every role may take any advisory
-- lock by default, so a read-only analyst could hold them and stall every station; only the
-- stations and the owner may take them here. This keeps the claims where they are (held by the
-- connection, dropped by the server when a station dies), which row locks could not do without
-- an open transaction for the whole session. Unlocking needs no grant: it frees only the
-- caller's own locks. The grants are per database (pg_catalog is per database).
DO $$
DECLARE
  f regprocedure;
  owner name := (SELECT tableowner FROM pg_tables WHERE schemaname = current_schema()
                   AND tablename = 'sessions');
BEGIN
  FOR f IN SELECT p.oid::regprocedure FROM pg_proc p
           WHERE p.pronamespace = 'pg_catalog'::regnamespace
             AND p.proname ~ '^pg_(try_)?advisory_(xact_)?lock(_shared)?$' LOOP
    EXECUTE format('REVOKE EXECUTE ON FUNCTION %s FROM PUBLIC', f);
    EXECUTE format('GRANT EXECUTE ON FUNCTION %s TO csf_station, %I', f, owner);
  END LOOP;
END $$;

-- No temporary tables or functions for anyone but the owner: a temporary object is the one
-- object a read-only role could otherwise create, and pg_temp comes first in name lookup.
DO $$ BEGIN
  EXECUTE format('REVOKE TEMPORARY ON DATABASE %I FROM PUBLIC', current_database());
END $$;

-- A finished or aborted session is closed, for every role: nothing is added to it, changed in
-- it or deleted from it (trials, readings, frame intervals, thresholds, participant link,
-- display profile history), and its state and person time do not change again. One exception: a file
-- written from the session after it finished (the report plot of an observer calibration) is
-- recorded as a new artifact; an artifact already stored does not change. The database owner
-- can lift the rule for a repair with ALTER TABLE ... DISABLE TRIGGER csf_closed.
-- The functions run as the caller (SECURITY INVOKER): they only read sessions, which every
-- role may read, and their search_path is fixed so no object of the caller's can stand in.
CREATE OR REPLACE FUNCTION csf_refuse_closed(sid bigint, op text, tab text) RETURNS void
LANGUAGE plpgsql SET search_path = pg_catalog, public AS $f$
DECLARE
  st text;
BEGIN
  IF sid IS NULL THEN RETURN; END IF;
  SELECT s.state INTO st FROM public.sessions s WHERE s.id = sid;
  IF st IN ('finished', 'aborted') AND NOT (tab = 'artifacts' AND op = 'INSERT') THEN
    RAISE EXCEPTION 'session % is % and closed: no % of its %', sid, st, lower(op), tab
      USING ERRCODE = '55000';
  END IF;
END $f$;

CREATE OR REPLACE FUNCTION csf_closed_session() RETURNS trigger LANGUAGE plpgsql
SET search_path = pg_catalog, public AS $f$
BEGIN
  IF TG_TABLE_NAME = 'sessions' THEN
    IF OLD.state IN ('finished', 'aborted') AND NEW.state IS DISTINCT FROM OLD.state THEN
      RAISE EXCEPTION 'session % is % and closed: its state does not change', OLD.id, OLD.state
        USING ERRCODE = '55000';
    END IF;
    IF OLD.state IN ('finished', 'aborted') AND NEW.person_s IS DISTINCT FROM OLD.person_s THEN
      RAISE EXCEPTION 'session % is % and closed: its person time does not change', OLD.id,
        OLD.state USING ERRCODE = '55000';
    END IF;
    RETURN NEW;
  END IF;
  -- An update checks the session a row leaves and the one it goes to.
  IF TG_OP <> 'INSERT' THEN
    PERFORM public.csf_refuse_closed(OLD.session_id, TG_OP, TG_TABLE_NAME);
  END IF;
  IF TG_OP <> 'DELETE' THEN
    PERFORM public.csf_refuse_closed(NEW.session_id, TG_OP, TG_TABLE_NAME);
  END IF;
  IF TG_OP = 'DELETE' THEN RETURN OLD; END IF;
  RETURN NEW;
END $f$;

-- A display's current profile, shared by every station, changes only to a profile a session of
-- the changing station measured on that display (or is set when the display has none). The
-- owner of the table may set any.
CREATE OR REPLACE FUNCTION csf_display_profile_guard() RETURNS trigger LANGUAGE plpgsql
SET search_path = pg_catalog, public AS $f$
BEGIN
  IF OLD.profile_id IS NULL OR NEW.profile_id IS NOT DISTINCT FROM OLD.profile_id
     OR pg_has_role(current_user, (SELECT c.relowner FROM pg_class c WHERE c.oid = TG_RELID), 'USAGE')
     OR EXISTS (SELECT 1 FROM public.display_profiles dp JOIN public.sessions s ON s.id = dp.session_id
                WHERE dp.display_id = NEW.id AND dp.profile_id = NEW.profile_id
                  AND s.station = current_user) THEN
    RETURN NEW;
  END IF;
  RAISE EXCEPTION 'display % has profile %: a station makes current only a profile one of its own '
    'sessions measured on it', OLD.name, OLD.profile_id USING ERRCODE = '42501';
END $f$;

DO $$
DECLARE
  t text;
  owner name := (SELECT tableowner FROM pg_tables WHERE schemaname = current_schema()
                   AND tablename = 'sessions');
BEGIN
  FOREACH t IN ARRAY ARRAY['trials', 'readings', 'frame_intervals', 'thresholds', 'artifacts',
                           'session_participants', 'display_profiles'] LOOP
    EXECUTE format('DROP TRIGGER IF EXISTS csf_closed ON %I', t);
    EXECUTE format('CREATE TRIGGER csf_closed BEFORE INSERT OR UPDATE OR DELETE ON %I '
                   'FOR EACH ROW EXECUTE FUNCTION csf_closed_session()', t);
  END LOOP;
  DROP TRIGGER IF EXISTS csf_closed ON sessions;
  CREATE TRIGGER csf_closed BEFORE UPDATE OF state, person_s ON sessions
    FOR EACH ROW EXECUTE FUNCTION csf_closed_session();
  DROP TRIGGER IF EXISTS csf_profile ON displays;
  CREATE TRIGGER csf_profile BEFORE UPDATE OF profile_id ON displays
    FOR EACH ROW EXECUTE FUNCTION csf_display_profile_guard();
  -- The functions belong to the schema's owner, like the tables they guard.
  EXECUTE format('ALTER FUNCTION csf_closed_session() OWNER TO %I', owner);
  EXECUTE format('ALTER FUNCTION csf_refuse_closed(bigint, text, text) OWNER TO %I', owner);
  EXECUTE format('ALTER FUNCTION csf_display_profile_guard() OWNER TO %I', owner);
END $$;
