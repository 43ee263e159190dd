// Compares two PNG images of the same size, pixel by pixel (RGB):
//   node viewer/tools/compare-png.mjs IMAGE REFERENCE [--mean 2.0] [--pixels 0.01] [--diff OUT.png]
// Passes when the mean absolute difference (0..255, over all channels) is at
// most --mean AND the fraction of pixels whose largest channel difference
// exceeds 48 is at most --pixels. Prints both figures. --diff writes an image
// of the differing pixels (red) over a faded copy of IMAGE.
// Exit: 0 within tolerance, 1 not (or sizes differ), 2 bad usage or unreadable file.
import fs from 'node:fs';
import { PNG } from 'pngjs';

const args = process.argv.slice(2);
const files = [];
const opt = { mean: 2.0, pixels: 0.01, diff: null };
for (let i = 0; i < args.length; ++i) {
  const a = args[i];
  if (a === '--mean') opt.mean = Number(args[++i]);
  else if (a === '--pixels') opt.pixels = Number(args[++i]);
  else if (a === '--diff') opt.diff = args[++i];
  else if (!a.startsWith('--')) files.push(a);
  else { console.error('compare-png: unknown argument ' + a); process.exit(2); }
}
if (files.length !== 2 || !(opt.mean >= 0) || !(opt.pixels >= 0)) {
  console.error('usage: compare-png.mjs IMAGE REFERENCE [--mean M] [--pixels F] [--diff OUT.png]');
  process.exit(2);
}
let a, b;
try {
  a = PNG.sync.read(fs.readFileSync(files[0]));
  b = PNG.sync.read(fs.readFileSync(files[1]));
} catch (e) {
  console.error('compare-png: ' + e.message);
  process.exit(2);
}
if (a.width !== b.width || a.height !== b.height) {
  console.log(`compare-png: sizes differ: ${files[0]} ${a.width}x${a.height}, ${files[1]} ${b.width}x${b.height}`);
  process.exit(1);
}
const n = a.width * a.height;
let sum = 0, differing = 0;
const diff = opt.diff ? new PNG({ width: a.width, height: a.height }) : null;
for (let p = 0; p < n; ++p) {
  let worst = 0;
  for (let c = 0; c < 3; ++c) {
    const d = Math.abs(a.data[4 * p + c] - b.data[4 * p + c]);
    sum += d;
    worst = Math.max(worst, d);
  }
  if (worst > 48) ++differing;
  if (diff) {
    const grey = (a.data[4 * p] + a.data[4 * p + 1] + a.data[4 * p + 2]) / 3;
    const faded = 200 + grey * 55 / 255;
    diff.data.set(worst > 48 ? [220, 30, 30, 255] : [faded, faded, faded, 255], 4 * p);
  }
}
const mean = sum / (3 * n), fraction = differing / n;
if (diff) fs.writeFileSync(opt.diff, PNG.sync.write(diff));
const ok = mean <= opt.mean && fraction <= opt.pixels;
console.log(`compare-png: mean difference ${mean.toFixed(3)} (at most ${opt.mean}), pixels differing ${(100 * fraction).toFixed(3)}% ` +
  `(at most ${(100 * opt.pixels).toFixed(3)}%): ${ok ? 'within tolerance' : 'NOT within tolerance'}`);
process.exit(ok ? 0 : 1);
