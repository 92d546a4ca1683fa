-- The tool table, keyed by tool number (the SQLite schema's 0001, in PostgreSQL's types).
CREATE TABLE tools (
    number      BIGINT           PRIMARY KEY CHECK (number BETWEEN 1 AND 9999),
    kind        TEXT             NOT NULL CHECK (kind IN ('ball', 'flat', 'bull')),
    radius      DOUBLE PRECISION NOT NULL CHECK (radius > 0),
    name        TEXT,
    tool_json   TEXT             NOT NULL,
    revision    BIGINT           NOT NULL DEFAULT 1,
    created_at  TIMESTAMPTZ      NOT NULL DEFAULT now(),
    updated_at  TIMESTAMPTZ      NOT NULL DEFAULT now()
);
