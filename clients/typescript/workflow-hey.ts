// The shop workflow through the SDK that @hey-api/openapi-ts generates from kerf's OpenAPI
// document (clients/generate writes generated/hey): a tool table and a machine, deburr as JSON
// and G-code, segment, contour, engagement, predict, then a job file submitted as JSON, followed
// until done, its one program and its outputs.zip. Every call goes through the generated SDK
// (which reads text and binary answers by their media type); `tsc` checks this file against the
// generated types, and an answer other than the documented success fails the run.
//
//     npx tsx workflow-hey.ts http://127.0.0.1:8080

import { client } from "./generated/hey/client.gen";
import {
  contour, deburr, deburrProgram, engagement, getJob, getJobOutputs, getJobProgram, listTools, predict,
  predictProgram, putMachine, putTool, segment, submitJob,
} from "./generated/hey/sdk.gen";
import type { DeburrRequest, JobFile, PredictRequest } from "./generated/hey/types.gen";

client.setConfig({ baseUrl: process.argv[2] ?? "http://127.0.0.1:8080" });

/** The data of a successful call; anything else ends the run with the problem document. */
function expect<T>(result: { data?: T; error?: unknown; response?: Response }, what: string): T {
  if (result.data === undefined) {
    throw new Error(`${what}: ${result.response?.status} ${JSON.stringify(result.error)}`);
  }
  return result.data;
}

function check(condition: boolean, message: string): void {
  if (!condition) throw new Error(message);
}

expect(await putTool({ path: { number: 7 }, body: { kind: "ball", radius: 3, flutes: 2, name: "R3 ball" } }), "put tool 7");
expect(await putTool({
  path: { number: 3 },
  body: {
    kind: "ball", radius: 3, flutes: 2, helix_deg: 30,
    shape_error: [{ angle_deg: 0, error: 0.004 }, { angle_deg: 90, error: 0.009 }],
    stiffness: {
      kind: "modal",
      x: [{ stiffness: 3000, frequency_hz: 1800, damping_ratio: 0.04 }],
      y: [{ stiffness: 3000, frequency_hz: 1800, damping_ratio: 0.04 }],
    },
  },
}), "put tool 3");
check(expect(await listTools(), "list tools").some((tool) => tool.number === 3), "tool 3 listed");
expect(await putMachine({
  path: { name: "vmc" }, body: { name: "vmc", block_time_ms: 2, max_feed: 10000, rapid_feed: 24000 },
}), "put machine");

const hole: DeburrRequest = {
  tool: 7, machine: "vmc", edge: "outer", cut_amount: 0.3, feed: 400,
  workpiece: { kind: "tube", origin: [0, 0, 0], inner_radius: 15, outer_radius: 25 },
  hole: { shape: "round", radius: 6 },
};
check(expect(await deburr({ body: hole }), "deburr").points.length > 100, "deburr points");
const program: string = expect(await deburrProgram({ body: hole, query: { dialect: "fanuc" } }), "deburr program");
check(program.includes("(KERF DEBURR)"), "deburr program text");

const segmented = expect(await segment({
  body: { tool: 7, machine: "vmc", feed: 1200, curve: { kind: "circle", centre: [30, 20, -2], radius: 20 } },
}), "segment");
check(segmented.chord_error > 0, "segment chord error");
const contoured = expect(await contour({
  body: {
    tool: 7, machine: "vmc", contour: [[0, 0], [60, 0], [60, 40], [0, 40]], side: "outside",
    depths: { top: 0, bottom: -4, step: 2 }, feed: 800, spindle_rpm: 8000,
  },
}), "contour");
check(contoured.layers.length === 2, "two contour layers");
const engaged = expect(await engagement({
  body: {
    tool: 7, spindle_rpm: 8000, feed_per_tooth: 0.04, flute_counts: [2, 4],
    stock: { polygon: [[0, 0], [100, 0], [100, 80], [0, 80]] },
    path: [[25, 25], [75, 25], [75, 31], [25, 31]],
  },
}), "engagement");
check((engaged.samples ?? []).length > 0, "engagement samples");
const dome: PredictRequest = {
  tool: 3, feed: 1600, spindle_rpm: 8000, cutting: { ktc: 2000, krc: 800, kac: 300 },
  path: { kind: "points", points: [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]] },
  stock: { kind: "plane", point: [0, 0, 0.1], normal: [0, 0, 1], min: [-5, -5], max: [8, 5] },
};
check(expect(await predict({ body: dome }), "predict").passes.length > 0, "predicted passes");
const corrected: string = expect(await predictProgram({ body: dome }), "predict program");
check(corrected.includes("KERF CORRECTED PATH"), "corrected program");

const job: JobFile = {
  name: "hey-api workflow",
  output: { program_number: 4712 },
  operations: [
    { operation: "deburr", ...hole },
    { operation: "segment", tool: 7, machine: "vmc", feed: 900, curve: { kind: "circle", centre: [0, 0, -1], radius: 12 } },
  ],
};
const submitted = expect(await submitJob({ body: job }), "submit job");
let view = expect(await getJob({ path: { id: submitted.id } }), "job");
for (let tries = 0; (view.status === "queued" || view.status === "running") && tries < 600; tries++) {
  await new Promise((resolve) => setTimeout(resolve, 200));
  view = expect(await getJob({ path: { id: submitted.id } }), "job");
}
check(view.status === "done", `job ${view.status}`);
const first = view.results?.[0];
check(first?.operation === "deburr" && first.result.points.length > 0, "the deburr result is typed by its operation");
const whole: string = expect(await getJobProgram({ path: { id: submitted.id } }), "job program");
check(whole.includes("O4712"), "job program number");
const zip: Blob = expect(await getJobOutputs({ path: { id: submitted.id } }), "outputs.zip");
const bytes = new Uint8Array(await zip.arrayBuffer());
check(bytes[0] === 0x50 && bytes[1] === 0x4b, "a zip archive");
console.log(`hey-api workflow: ${program.length} B deburr program, job ${submitted.id}, ${bytes.length} B zip`);
