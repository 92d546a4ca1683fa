-- The tool table, keyed by tool number like a machine's tool table.
-- `tool_json` holds the whole tool record (solver::tool::Tool); kind, radius and name are
-- copied into columns for listing and inspection with plain SQL.
CREATE TABLE tools (
    number      INTEGER PRIMARY KEY CHECK (number BETWEEN 1 AND 9999),
    kind        TEXT    NOT NULL CHECK (kind IN ('ball', 'flat', 'bull')),
    radius      REAL    NOT NULL CHECK (radius > 0),
    name        TEXT,
    tool_json   TEXT    NOT NULL,
    revision    INTEGER NOT NULL DEFAULT 1,
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
) STRICT;
