-- Machines: controller profiles keyed by name (the SQLite schema's 0003, in PostgreSQL's types).
CREATE TABLE machines (
    name           TEXT             PRIMARY KEY CHECK (length(name) BETWEEN 1 AND 64),
    block_time_ms  DOUBLE PRECISION NOT NULL CHECK (block_time_ms > 0),
    max_feed       DOUBLE PRECISION NOT NULL CHECK (max_feed > 0),
    dialect        TEXT             NOT NULL CHECK (dialect IN ('fanuc', 'linuxcnc')),
    machine_json   TEXT             NOT NULL,
    revision       BIGINT           NOT NULL DEFAULT 1,
    created_at     TIMESTAMPTZ      NOT NULL DEFAULT now(),
    updated_at     TIMESTAMPTZ      NOT NULL DEFAULT now()
);
