-- Machine profiles name one of seven posts (the SQLite schema's 0008): the dialect column's check
-- lists them all.
ALTER TABLE machines DROP CONSTRAINT machines_dialect_check;
ALTER TABLE machines ADD CONSTRAINT machines_dialect_check
    CHECK (dialect IN ('fanuc', 'haas', 'linuxcnc', 'sinumerik', 'heidenhain', 'heidenhain_iso', 'grbl'));
