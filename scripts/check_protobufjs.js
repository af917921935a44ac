// Reads `xbandsim serve` (docs/live.md) the way mayara's v1 web client does
// (keesverruijt/mayara, web/v1/gui/control.js and viewer.js): it fetches /v1/api/radars,
// parses the served /v1/api/RadarMessage.proto with protobufjs (the library that client
// decodes with), looks up ".RadarMessage", opens the description's streamUrl and decodes every
// binary message, and opens its controlUrl for the JSON control values. It checks that a
// revolution's every angle arrives, every spoke holds maxSpokeLen samples, every sample is an
// index into the legend, and every control sends its value.
//
// Usage: node scripts/check_protobufjs.js XBANDSIM_BINARY SCENE
// (protobufjs 7.6.6 and ws 8.23.1 from the npm registry, installed by scripts/test.sh into
// target/check-node).
"use strict";
const { spawn } = require("child_process");
const path = require("path");
const modules = path.join(__dirname, "..", "target", "check-node", "node_modules");
const protobuf = require(path.join(modules, "protobufjs"));
const WebSocket = require(path.join(modules, "ws"));

const [binary, scene] = process.argv.slice(2);
const server = spawn(binary, ["serve", scene, "--listen", "127.0.0.1:0", "--speed", "4"]);
let failed = 0;
function check(ok, what) {
  console.log((ok ? "ok   " : "FAIL ") + what);
  if (!ok) failed++;
}
let out = "";
server.stdout.on("data", async (chunk) => {
  out += chunk.toString();
  const m = out.match(/ on (http:\/\/[0-9.:]+)\/ /);
  if (!m || !out.includes("Ctrl-C stops") || server.started) return;
  server.started = true;
  try {
    await run(m[1]);
  } catch (e) {
    check(false, "the client ran: " + e);
  }
  server.kill("SIGINT");
});
server.on("exit", (code) => {
  check(code === 0, `the server stopped cleanly (exit ${code})`);
  process.exit(failed ? 1 : 0);
});

async function run(base) {
  const radars = await (await fetch(base + "/v1/api/radars")).json();
  const r = radars["1"];
  const root = protobuf.parse(await (await fetch(base + "/v1/api/RadarMessage.proto")).text()).root;
  const RadarMessage = root.lookupType(".RadarMessage");
  const legend = r.legend.pixels.map((p) => p.color);
  const controls = new Map();
  const angles = new Set();
  let spokes = 0, badLength = 0, badIndex = 0;
  const cws = new WebSocket(r.controlUrl);
  cws.on("message", (m) => {
    const v = JSON.parse(m.toString());
    controls.set(v.id, v);
  });
  const ws = new WebSocket(r.streamUrl);
  ws.binaryType = "arraybuffer";
  ws.on("message", (data) => {
    const message = RadarMessage.decode(new Uint8Array(data));
    for (const s of message.spokes) {
      spokes++;
      angles.add(s.angle);
      if (s.data.length !== r.maxSpokeLen) badLength++;
      for (const v of s.data) if (v >= legend.length) badIndex++;
    }
  });
  const period = r.rotationPeriodS / 4;
  await new Promise((done) => setTimeout(done, Math.max(2.5 * period, 1.0) * 1000));
  ws.close();
  cws.close();
  check(angles.size === r.spokesPerRevolution,
    `protobufjs decoded ${spokes} spokes, ${angles.size} of ${r.spokesPerRevolution} angles`);
  check(spokes > 0 && badLength === 0, `every spoke holds ${r.maxSpokeLen} samples (${badLength} do not)`);
  check(spokes > 0 && badIndex === 0, `every sample indexes the legend's ${legend.length} colours (${badIndex} do not)`);
  const ids = Object.keys(r.controls);
  check(ids.every((id) => controls.has(id)), `the control stream sent every control's value (${[...controls.keys()]})`);
}
