-- Machine profiles name the units of the requests that name them (`mm` or `inch`; the profile's
-- own values stay in mm).
ALTER TABLE machines ADD COLUMN units TEXT NOT NULL DEFAULT 'mm' CHECK (units IN ('mm', 'inch'));
