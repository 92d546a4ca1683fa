-- Job storage that cannot fill the disk (issue 13; the SQLite schema's 0004). Results and
-- programs of new jobs are stored gzip-compressed (`result_gz`, `gcode_gz`; `result_json` is then
-- '' and `gcode` NULL), with their uncompressed sizes; rows stored before keep their text.
-- `jobs.stored_bytes` is what a job takes in the store (its job file and its compressed
-- results): the job store's quota is on their sum.
ALTER TABLE job_results ADD COLUMN result_gz BYTEA;
ALTER TABLE job_results ADD COLUMN result_bytes BIGINT NOT NULL DEFAULT 0;
ALTER TABLE job_results ADD COLUMN gcode_gz BYTEA;
ALTER TABLE job_results ADD COLUMN gcode_bytes BIGINT NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN stored_bytes BIGINT NOT NULL DEFAULT 0;

UPDATE job_results SET result_bytes = octet_length(result_json), gcode_bytes = COALESCE(octet_length(gcode), 0);
UPDATE jobs SET stored_bytes = octet_length(job_json)
    + COALESCE((SELECT SUM(result_bytes + gcode_bytes) FROM job_results WHERE job_id = jobs.id), 0);

-- Retention: finished jobs by age.
CREATE INDEX jobs_by_finish ON jobs (finished_at) WHERE status IN ('done', 'failed', 'cancelled');
