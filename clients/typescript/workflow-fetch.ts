// The shop workflow through openapi-fetch, typed by openapi-typescript from kerf's OpenAPI
// document (clients/generate writes generated/schema.d.ts): a tool table and a machine, deburr
// as JSON and G-code, segment, contour, engagement, predict, then a job file submitted as a form,
// followed until done, its one program and its outputs.zip. Every call goes through the typed
// client; `tsc` checks this file against the generated types, and an answer other than the
// documented success fails the run.
//
//     npx tsx workflow-fetch.ts http://127.0.0.1:8080

import { readFileSync } from "node:fs";
import createClient from "openapi-fetch";
import type { components, paths } from "./generated/schema.d.ts";

type Schemas = components["schemas"];

const baseUrl = process.argv[2] ?? "http://127.0.0.1:8080";
const client = createClient<paths>({ baseUrl });

/** The data of a successful call; anything else ends the run with the problem document. */
function expect<T>(result: { data?: T; error?: unknown; response: Response }, what: string): T {
  if (result.data === undefined) {
    throw new Error(`${what}: ${result.response.status} ${JSON.stringify(result.error)}`);
  }
  return result.data;
}

function check(condition: boolean, message: string): void {
  if (!condition) throw new Error(message);
}

const ball: Schemas["Tool"] = { kind: "ball", radius: 3, flutes: 2, name: "R3 ball" };
expect(await client.PUT("/api/v1/tools/{number}", { params: { path: { number: 7 } }, body: ball }), "put tool 7");
const finishing: Schemas["Tool"] = {
  kind: "ball", radius: 3, flutes: 2, helix_deg: 30,
  shape_error: [{ angle_deg: 0, error: 0.004 }, { angle_deg: 90, error: 0.009 }],
  stiffness: {
    kind: "modal",
    x: [{ stiffness: 3000, frequency_hz: 1800, damping_ratio: 0.04 }],
    y: [{ stiffness: 3000, frequency_hz: 1800, damping_ratio: 0.04 }],
  },
};
expect(await client.PUT("/api/v1/tools/{number}", { params: { path: { number: 3 } }, body: finishing }), "put tool 3");
const tools = expect(await client.GET("/api/v1/tools"), "list tools");
check(tools.some((tool) => tool.number === 7), "tool 7 listed");
const vmc: Schemas["MachineProfile"] = { name: "vmc", block_time_ms: 2, max_feed: 10000, rapid_feed: 24000 };
expect(await client.PUT("/api/v1/machines/{name}", { params: { path: { name: "vmc" } }, body: vmc }), "put machine");

const hole: Schemas["DeburrRequest"] = {
  tool: 7, machine: "vmc", edge: "outer", cut_amount: 0.3, feed: 400,
  workpiece: { kind: "tube", origin: [0, 0, 0], inner_radius: 15, outer_radius: 25 },
  hole: { shape: "round", radius: 6 },
};
const deburred: Schemas["DeburrAnswer"] = expect(await client.POST("/api/v1/deburr", { body: hole }), "deburr");
check(deburred.points.length > 100, "deburr points");
const program: string = expect(
  await client.POST("/api/v1/deburr/program", { body: hole, params: { query: { dialect: "linuxcnc" } }, parseAs: "text" }),
  "deburr program",
);
check(program.includes("(KERF DEBURR)") && program.includes("M30"), "deburr program text");

const segmented = expect(await client.POST("/api/v1/segment", {
  body: { tool: 7, machine: "vmc", feed: 1200, curve: { kind: "circle", centre: [30, 20, -2], radius: 20 } },
}), "segment");
check(segmented.chord_error > 0, "segment chord error");

const contoured = expect(await client.POST("/api/v1/contour", {
  body: {
    tool: 7, machine: "vmc", contour: [[0, 0], [60, 0], [60, 40], [0, 40]], side: "outside",
    depths: { top: 0, bottom: -4, step: 2 }, feed: 800, spindle_rpm: 8000,
  },
}), "contour");
check(contoured.layers.length === 2, "two contour layers");

const engaged = expect(await client.POST("/api/v1/engagement", {
  body: {
    tool: 7, spindle_rpm: 8000, feed_per_tooth: 0.04, flute_counts: [2, 4],
    stock: { polygon: [[0, 0], [100, 0], [100, 80], [0, 80]] },
    path: [[25, 25], [75, 25], [75, 31], [25, 31]],
  },
}), "engagement");
check((engaged.samples ?? []).length > 0 && engaged.tool.number === 7, "engagement samples");

const dome: Schemas["PredictRequest"] = {
  tool: 3, feed: 1600, spindle_rpm: 8000, cutting: { ktc: 2000, krc: 800, kac: 300 },
  path: { kind: "points", points: [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]] },
  stock: { kind: "plane", point: [0, 0, 0.1], normal: [0, 0, 1], min: [-5, -5], max: [8, 5] },
};
const predicted = expect(await client.POST("/api/v1/predict", { body: dome }), "predict");
check(predicted.passes.length > 0, "predicted passes");
const corrected: string = expect(await client.POST("/api/v1/predict/program", { body: dome, parseAs: "text" }), "predict program");
check(corrected.includes("KERF CORRECTED PATH"), "corrected program");

// The job file goes as a form with its `file` field, as the document describes it.
const shop = readFileSync(new URL("../../examples/shop-job.toml", import.meta.url), "utf8");
const submitted = expect(await client.POST("/api/v1/jobs", {
  body: { file: shop },
  bodySerializer: () => {
    const form = new FormData();
    form.append("file", new Blob([shop], { type: "application/toml" }), "shop-job.toml");
    return form;
  },
}), "submit job");
let job = expect(await client.GET("/api/v1/jobs/{id}", { params: { path: { id: submitted.id } } }), "job");
for (let tries = 0; (job.status === "queued" || job.status === "running") && tries < 600; tries++) {
  await new Promise((resolve) => setTimeout(resolve, 200));
  job = expect(await client.GET("/api/v1/jobs/{id}", { params: { path: { id: submitted.id } } }), "job");
}
check(job.status === "done", `job ${job.status}`);
const operations = (job.results ?? []).map((result) => result.operation);
check(operations.join() === "deburr,contour,segment", operations.join());
const first = job.results?.[0];
check(first?.operation === "deburr" && first.result.points.length > 0, "the deburr result is typed by its operation");
const whole: string = expect(
  await client.GET("/api/v1/jobs/{id}/program", { params: { path: { id: submitted.id } }, parseAs: "text" }),
  "job program",
);
check(whole.includes("O4711"), "job program number");
const zip: Blob = expect(
  await client.GET("/api/v1/jobs/{id}/outputs.zip", { params: { path: { id: submitted.id } }, parseAs: "blob" }),
  "outputs.zip",
);
const bytes = new Uint8Array(await zip.arrayBuffer());
check(bytes[0] === 0x50 && bytes[1] === 0x4b, "a zip archive");
console.log(`openapi-fetch workflow: ${program.length} B deburr program, job ${submitted.id}, ${bytes.length} B zip`);
