-- Machines: controller profiles keyed by name (issue 3; api.md, Machines; chord.md §2.1, §6.4).
-- `machine_json` holds the whole profile (solver::chord::MachineProfile, with its name);
-- block_time_ms, max_feed and dialect are copied into columns for listing and inspection with
-- plain SQL.
CREATE TABLE machines (
    name           TEXT    PRIMARY KEY CHECK (length(name) BETWEEN 1 AND 64),
    block_time_ms  REAL    NOT NULL CHECK (block_time_ms > 0),
    max_feed       REAL    NOT NULL CHECK (max_feed > 0),
    dialect        TEXT    NOT NULL CHECK (dialect IN ('fanuc', 'linuxcnc')),
    machine_json   TEXT    NOT NULL,
    revision       INTEGER NOT NULL DEFAULT 1,
    created_at     TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at     TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
) STRICT;
