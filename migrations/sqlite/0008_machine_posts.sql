-- Machine profiles name one of seven posts (docs/guide/gcode.md): the dialect column's check lists
-- them all. SQLite cannot change a column's check, so the table is copied into one with the new
-- check.
CREATE TABLE machines_posts (
    name           TEXT    PRIMARY KEY CHECK (length(name) BETWEEN 1 AND 64),
    block_time_ms  REAL    NOT NULL CHECK (block_time_ms > 0),
    max_feed       REAL    NOT NULL CHECK (max_feed > 0),
    dialect        TEXT    NOT NULL CHECK (dialect IN ('fanuc', 'haas', 'linuxcnc', 'sinumerik', 'heidenhain', 'heidenhain_iso', 'grbl')),
    machine_json   TEXT    NOT NULL,
    revision       INTEGER NOT NULL DEFAULT 1,
    created_at     TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at     TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
) STRICT;
INSERT INTO machines_posts (name, block_time_ms, max_feed, dialect, machine_json, revision, created_at, updated_at)
    SELECT name, block_time_ms, max_feed, dialect, machine_json, revision, created_at, updated_at FROM machines;
DROP TABLE machines;
ALTER TABLE machines_posts RENAME TO machines;
