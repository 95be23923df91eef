// ONNX Runtime (CPU execution provider; the native library inside npm's
// onnxruntime-node, bench/peers/package.json) running the ONNX export of a depth
// network: one of the peers bench/peers/run.sh puts beside `ampi bench network`.
// Same protocol as the other peers: a 1 x 3 x H x W float32 .npy input, one JSON line per
// thread count on stdout, the output saved as H x W .npy.
//
//   node bench/peers/ort_peer.js --model lite.onnx --input rgb_nchw.npy --threads 1,2 --runs 5 --save out/ort
'use strict';
const fs = require('fs');
const { performance } = require('perf_hooks');

let ort;
try {
  ort = require('onnxruntime-node');
} catch (e) {
  console.error(`ort_peer.js: onnxruntime-node is not installed in ${__dirname}/node_modules ` +
                '(run bench/peers/run.sh or: cd bench/peers && ONNXRUNTIME_NODE_INSTALL=skip npm ci)');
  process.exit(1);
}

function parseArgs(argv) {
  const o = { threads: [1, 2], runs: 5, warmup: 1, save: '' };
  for (let i = 0; i < argv.length; i += 2) {
    const [name, value] = [argv[i], argv[i + 1]];
    if (value === undefined) throw new Error(`${name}: needs a value`);
    if (name === '--model') o.model = value;
    else if (name === '--input') o.input = value;
    else if (name === '--save') o.save = value;
    else if (name === '--threads') o.threads = value.split(',').map(Number);
    else if (name === '--runs') o.runs = Math.max(1, Number(value));
    else if (name === '--warmup') o.warmup = Math.max(0, Number(value));
    else throw new Error(`unknown option ${name}`);
  }
  if (!o.model || !o.input) throw new Error('--model and --input are required');
  if (o.threads.some((n) => !Number.isInteger(n) || n < 1)) throw new Error('--threads: bad list');
  return o;
}

// A little-endian float32, C-order .npy file (what numpy writes) as {shape, data}.
function readNpy(path) {
  const buf = fs.readFileSync(path);
  if (buf.toString('latin1', 0, 6) !== '\x93NUMPY') throw new Error(`${path}: not an .npy file`);
  const major = buf[6];
  const headerLen = major === 1 ? buf.readUInt16LE(8) : buf.readUInt32LE(8);
  const start = major === 1 ? 10 : 12;
  const header = buf.toString('latin1', start, start + headerLen);
  if (!/'descr':\s*'<f4'/.test(header) || /'fortran_order':\s*True/.test(header))
    throw new Error(`${path}: expected little-endian float32 in C order`);
  const shape = header.match(/'shape':\s*\(([^)]*)\)/)[1].split(',').filter((s) => s.trim()).map(Number);
  const bytes = buf.subarray(start + headerLen);
  const data = new Float32Array(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length));
  if (data.length !== shape.reduce((a, b) => a * b, 1)) throw new Error(`${path}: truncated data`);
  return { shape, data };
}

function writeNpy(path, shape, data) {
  let header = `{'descr': '<f4', 'fortran_order': False, 'shape': (${shape.join(', ')}${shape.length === 1 ? ',' : ''}), }`;
  const total = 10 + header.length + 1;
  header += ' '.repeat((64 - (total % 64)) % 64) + '\n';
  const prefix = Buffer.alloc(10);
  prefix.write('\x93NUMPY', 0, 'latin1');
  prefix[6] = 1;
  prefix[7] = 0;
  prefix.writeUInt16LE(header.length, 8);
  fs.writeFileSync(path, Buffer.concat([prefix, Buffer.from(header, 'latin1'),
                                       Buffer.from(data.buffer, data.byteOffset, data.byteLength)]));
}

async function main() {
  const o = parseArgs(process.argv.slice(2));
  const input = readNpy(o.input);
  if (input.shape.length !== 4 || input.shape[0] !== 1 || input.shape[1] !== 3)
    throw new Error(`${o.input}: expected a 1 x 3 x H x W array, got [${input.shape}]`);
  const feeds = { rgb: new ort.Tensor('float32', input.data, input.shape) };
  for (const threads of o.threads) {
    // One session per thread count: ONNX Runtime fixes its thread pool at creation.
    const session = await ort.InferenceSession.create(o.model, {
      executionProviders: ['cpu'],
      graphOptimizationLevel: 'all',
      executionMode: 'sequential',
      intraOpNumThreads: threads,
      interOpNumThreads: 1,
    });
    let out;
    for (let i = 0; i < o.warmup; ++i) out = (await session.run(feeds)).disparity;
    const ms = [];
    for (let i = 0; i < o.runs; ++i) {
      const start = performance.now();
      out = (await session.run(feeds)).disparity;
      ms.push(performance.now() - start);
    }
    console.log(JSON.stringify({ engine: 'onnxruntime', version: ort.env.versions.common, threads, ms }));
    if (o.save) writeNpy(`${o.save}.t${threads}.npy`, out.dims.slice(2), out.data);
    await session.release();
  }
}

main().catch((e) => {
  console.error(`ort_peer.js: ${e.message}`);
  process.exit(1);
});
