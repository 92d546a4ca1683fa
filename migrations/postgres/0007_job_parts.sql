-- Jobs split inside one operation (issue 12): a worker that claims an operation whose work
-- divides (prediction passes, engagement candidates) turns its chunk into the first of the
-- operation's parts and queues the others and a finish step, which becomes claimable once every
-- part is done and merges their outputs into the operation's result and program.
--
-- `operation` is the operation's index (`position` stays the chunk's unique number within its
-- job); `kind` is 'whole' (the operation solved whole, as before), 'part' (units
-- [units_from, units_to) of it) or 'finish'. `work` is the estimated core-seconds, `weight` the
-- chunk's share of its operation (an operation's chunks weigh 1 together; the job's progress is
-- the weighted sum of its chunks' progress over its operations). A done part keeps its output,
-- gzip-compressed CBOR, with its uncompressed length and solve time, until the finish step has
-- merged it (counted in `jobs.stored_bytes` meanwhile).
ALTER TABLE job_chunks ADD COLUMN operation BIGINT;
UPDATE job_chunks SET operation = position;
ALTER TABLE job_chunks ALTER COLUMN operation SET NOT NULL;
ALTER TABLE job_chunks ADD COLUMN kind TEXT NOT NULL DEFAULT 'whole' CHECK (kind IN ('whole', 'part', 'finish'));
ALTER TABLE job_chunks ADD COLUMN units_from BIGINT;
ALTER TABLE job_chunks ADD COLUMN units_to BIGINT;
ALTER TABLE job_chunks ADD COLUMN work DOUBLE PRECISION NOT NULL DEFAULT 0;
ALTER TABLE job_chunks ADD COLUMN weight DOUBLE PRECISION NOT NULL DEFAULT 1;
ALTER TABLE job_chunks ADD COLUMN output_gz BYTEA;
ALTER TABLE job_chunks ADD COLUMN output_bytes BIGINT NOT NULL DEFAULT 0;
ALTER TABLE job_chunks ADD COLUMN solve_seconds DOUBLE PRECISION NOT NULL DEFAULT 0;

-- The claim's scan in its new order (job, operation, chunk), and a finish step's look at its parts.
DROP INDEX job_chunks_queued;
CREATE INDEX job_chunks_queued ON job_chunks (job_id, operation, position) WHERE status = 'queued';
CREATE INDEX job_chunks_by_operation ON job_chunks (job_id, operation, kind);
