-- Jobs uploaded as job files (issue 7). `job_json` is the resolved job (tools inline), so a job
-- runs without the tool table and identical jobs share `content_hash`.
CREATE TABLE jobs (
    id            INTEGER PRIMARY KEY AUTOINCREMENT,
    name          TEXT,
    status        TEXT    NOT NULL CHECK (status IN ('queued', 'running', 'done', 'failed', 'cancelled')),
    progress      REAL    NOT NULL DEFAULT 0 CHECK (progress BETWEEN 0 AND 1),
    content_hash  TEXT    NOT NULL,
    job_json      TEXT    NOT NULL,
    operations    TEXT    NOT NULL,  -- JSON array of operation names, for listings
    attempts      INTEGER NOT NULL DEFAULT 0,
    error         TEXT,
    error_field   TEXT,
    submitted_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    started_at    TEXT,
    finished_at   TEXT,
    heartbeat_at  TEXT
) STRICT;

CREATE INDEX jobs_by_status ON jobs (status, id);
CREATE INDEX jobs_by_hash ON jobs (content_hash, status);

-- One row per operation of a finished job.
CREATE TABLE job_results (
    job_id         INTEGER NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
    position       INTEGER NOT NULL,
    operation      TEXT    NOT NULL,
    result_json    TEXT    NOT NULL,
    gcode          TEXT,
    gcode_problem  TEXT,
    PRIMARY KEY (job_id, position)
) STRICT;
