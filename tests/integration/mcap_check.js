// Reads an MCAP file of `marsala-monitor export` with the MCAP library from npm (@mcap/core), an implementation
// independent of the project's writer, and checks it against the run folder it came from:
//   - the indexed reader (summary, chunk indexes, CRCs) and the stream reader (every record, CRCs) both read it and
//     see the same messages;
//   - every message decodes against its channel's embedded JSON Schema (JSON.parse, then every required field of the
//     schema present with its type, recursively);
//   - the counts: /robots steps + 1, /terrain 1 + floor(steps / K) (+ 1 when K does not divide steps), /events the
//     lines of events.log; the Statistics record agrees;
//   - the first and the last /terrain, cell by cell, against terrain_initial.asc and terrain_final.asc (float32);
//   - the last /robots against summary.json's per_agent: x, y, z, material, state.
// Usage: node mcap_check.js NODE_MODULES FILE.mcap RUN_DIR K
"use strict";
const fs = require("fs");
const path = require("path");

const [modules, file, runDir, everyText] = process.argv.slice(2);
const { McapIndexedReader, McapStreamReader } = require(path.join(modules, "@mcap", "core"));
const every = Number(everyText);

function fail(message) {
  console.error(`mcap_check: ${message}`);
  process.exit(1);
}

// Every required field of `schema` present in `value` with its type, recursively.
function conforms(value, schema, where) {
  const type = schema.type;
  if (type === "object") {
    if (typeof value !== "object" || value === null || Array.isArray(value)) fail(`${where}: not an object`);
    for (const name of schema.required || []) {
      if (!(name in value)) fail(`${where}: required field '${name}' missing`);
    }
    for (const [name, sub] of Object.entries(schema.properties || {})) {
      if (name in value) conforms(value[name], sub, `${where}.${name}`);
    }
  } else if (type === "array") {
    if (!Array.isArray(value)) fail(`${where}: not an array`);
    if (schema.items) value.forEach((v, i) => conforms(v, schema.items, `${where}[${i}]`));
  } else if (type === "integer") {
    if (!Number.isInteger(value)) fail(`${where}: not an integer`);
  } else if (type === "number") {
    if (typeof value !== "number") fail(`${where}: not a number`);
  } else if (type === "string" || type === "boolean") {
    if (typeof value !== type) fail(`${where}: not a ${type}`);
  }
}

function readAsc(file) {
  const lines = fs.readFileSync(file, "utf8").split("\n");
  const header = {};
  let i = 0;
  for (; i < 6; ++i) {
    const [key, val] = lines[i].trim().split(/\s+/);
    header[key.toLowerCase()] = Number(val);
  }
  const rows = [];
  for (; rows.length < header.nrows; ++i) rows.push(lines[i].trim().split(/\s+/).map(Number));
  return { ...header, rows };
}

// A foxglove.Grid against an .asc terrain: size, placement and every cell's float32 height.
function sameTerrain(grid, asc, name) {
  const rows = asc.nrows, cols = asc.ncols;
  if (grid.column_count !== cols || grid.row_stride !== 4 * cols || grid.cell_stride !== 4)
    fail(`${name}: grid of ${grid.column_count} columns, the file has ${cols}`);
  if (grid.cell_size.x !== asc.cellsize || grid.pose.position.x !== asc.xllcorner || grid.pose.position.y !== asc.yllcorner)
    fail(`${name}: the grid's corner or cell size differs from the file's`);
  if (grid.fields.length !== 1 || grid.fields[0].name !== "height" || grid.fields[0].type !== 7)
    fail(`${name}: expected one FLOAT32 field 'height'`);
  const bytes = Buffer.from(grid.data, "base64");
  if (bytes.length !== rows * cols * 4) fail(`${name}: ${bytes.length} bytes of data for ${rows} x ${cols} cells`);
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.length);
  for (let r = 0; r < rows; ++r)
    for (let c = 0; c < cols; ++c) {
      const got = view.getFloat32(((rows - 1 - r) * cols + c) * 4, true);
      if (got !== Math.fround(asc.rows[r][c])) fail(`${name}: cell (${r}, ${c}) is ${got}, the file says ${asc.rows[r][c]}`);
    }
}

function close(a, b, tolerance) {
  return Math.abs(a - b) <= tolerance * Math.max(1, Math.abs(a), Math.abs(b));
}

async function indexedMessages(buffer) {
  const readable = {
    size: async () => BigInt(buffer.length),
    read: async (offset, length) => buffer.subarray(Number(offset), Number(offset + length)),
  };
  const reader = await McapIndexedReader.Initialize({ readable });
  if (reader.chunkIndexes.length === 0) fail("no chunk index in the summary");
  if (!reader.statistics) fail("no Statistics record");
  const schemas = new Map();
  for (const [id, s] of reader.schemasById) schemas.set(id, JSON.parse(new TextDecoder().decode(s.data)));
  const byTopic = new Map();
  let count = 0;
  for await (const m of reader.readMessages()) {
    const channel = reader.channelsById.get(m.channelId);
    const value = JSON.parse(new TextDecoder().decode(m.data));
    conforms(value, schemas.get(channel.schemaId), `${channel.topic} #${m.sequence}`);
    if (!byTopic.has(channel.topic)) byTopic.set(channel.topic, []);
    byTopic.get(channel.topic).push({ time: m.logTime, value });
    ++count;
  }
  if (BigInt(count) !== reader.statistics.messageCount)
    fail(`Statistics says ${reader.statistics.messageCount} messages, the indexed reader read ${count}`);
  return byTopic;
}

function streamedCount(buffer) {
  const reader = new McapStreamReader({ validateCrcs: true });
  reader.append(buffer);
  let messages = 0, footer = false;
  for (let record; (record = reader.nextRecord()) !== undefined; ) {
    if (record.type === "Message") ++messages;
    if (record.type === "Footer") footer = true;
  }
  if (!footer || !reader.done()) fail("the stream reader did not reach the footer");
  return messages;
}

async function main() {
  const buffer = fs.readFileSync(file);
  const byTopic = await indexedMessages(buffer);
  const streamed = streamedCount(buffer);
  const summary = JSON.parse(fs.readFileSync(path.join(runDir, "summary.json"), "utf8"));
  const steps = summary.steps;
  const eventLines = fs.readFileSync(path.join(runDir, "events.log"), "utf8").split("\n").filter((l) => l.length > 0);
  const want = {
    "/robots": steps + 1,
    "/terrain": 1 + Math.floor(steps / every) + (steps % every === 0 ? 0 : 1),
    "/events": eventLines.length,
  };
  let total = 0;
  for (const [topic, n] of Object.entries(want)) {
    const got = (byTopic.get(topic) || []).length;
    if (got !== n) fail(`${topic}: ${got} messages, expected ${n}`);
    total += n;
  }
  if (streamed !== total) fail(`the stream reader read ${streamed} messages, the indexed reader ${total}`);

  const terrains = byTopic.get("/terrain").sort((a, b) => (a.time < b.time ? -1 : a.time > b.time ? 1 : 0));
  sameTerrain(terrains[0].value, readAsc(path.join(runDir, "terrain_initial.asc")), "first /terrain");
  sameTerrain(terrains[terrains.length - 1].value, readAsc(path.join(runDir, "terrain_final.asc")), "last /terrain");

  const robots = byTopic.get("/robots");
  const last = robots[robots.length - 1].value;
  for (const agent of summary.per_agent.filter((a) => a.admitted)) {
    const entity = last.entities.find((e) => e.id === `agent-${agent.agent_id}`);
    if (!entity) fail(`agent ${agent.agent_id} missing from the last /robots`);
    const meta = Object.fromEntries(entity.metadata.map((kv) => [kv.key, kv.value]));
    const pose = entity.cylinders[0].pose.position;
    if (Number(meta.x_m) !== agent.x_m || Number(meta.y_m) !== agent.y_m || pose.x !== agent.x_m || pose.y !== agent.y_m)
      fail(`agent ${agent.agent_id}: at (${meta.x_m}, ${meta.y_m}), summary.json says (${agent.x_m}, ${agent.y_m})`);
    if (!close(Number(meta.z_m), agent.z_m, 1e-12)) fail(`agent ${agent.agent_id}: z ${meta.z_m}, summary.json ${agent.z_m}`);
    if (!close(Number(meta.material_m3), agent.material_m3, 1e-9))
      fail(`agent ${agent.agent_id}: material ${meta.material_m3}, summary.json ${agent.material_m3}`);
    if (meta.state !== agent.state) fail(`agent ${agent.agent_id}: state ${meta.state}, summary.json ${agent.state}`);
  }
  console.log(`ok: ${total} messages (${want["/robots"]} robots, ${want["/terrain"]} terrains, ${want["/events"]} events) ` +
              `read by both readers, every one against its schema; terrains and last poses match the run folder`);
}

main().catch((e) => fail(e.stack || String(e)));
