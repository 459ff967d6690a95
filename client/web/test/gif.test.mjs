// The page's GIF encoder (src/page/gif.js) against a GIF89a decoder written here from the
// format's description: every frame must decode to exactly the quantized pixels, through code
// width changes and dictionary resets (random pixels fill the 4096-entry table quickly).
// The browser test also has Chromium decode a GIF the page made.
import assert from "node:assert/strict";
import { test } from "node:test";

import { encodeGif, quantize } from "../src/page/gif.js";

function lzwDecode(data, minSize, count) {
  const out = new Uint8Array(count);
  let n = 0;
  const clear = 1 << minSize;
  const eoi = clear + 1;
  let size = minSize + 1;
  let dict = [];
  const reset = () => {
    dict = [];
    for (let i = 0; i < clear; i++) dict.push([i]);
    dict.push(null, null);
    size = minSize + 1;
  };
  reset();
  let prev = null;
  let acc = 0;
  let bits = 0;
  let pos = 0;
  for (;;) {
    while (bits < size) {
      assert.ok(pos < data.length, "LZW data ended without an end code");
      acc |= data[pos++] << bits;
      bits += 8;
    }
    const code = acc & ((1 << size) - 1);
    acc >>>= size;
    bits -= size;
    if (code === clear) {
      reset();
      prev = null;
      continue;
    }
    if (code === eoi) break;
    let entry;
    if (code < dict.length) entry = dict[code];
    else if (code === dict.length && prev) entry = [...prev, prev[0]];
    else assert.fail(`bad code ${code} with ${dict.length} entries`);
    for (const v of entry) out[n++] = v;
    if (prev && dict.length < 4096) dict.push([...prev, entry[0]]);
    if (dict.length === 1 << size && size < 12) size++;
    prev = entry;
  }
  assert.equal(n, count, "pixel count");
  return out;
}

function decodeGif(bytes) {
  let p = 0;
  const u8 = () => bytes[p++];
  const u16 = () => bytes[p++] | (bytes[p++] << 8);
  assert.equal(String.fromCharCode(...bytes.subarray(0, 6)), "GIF89a");
  p = 6;
  const width = u16();
  const height = u16();
  const flags = u8();
  p += 2;
  if (flags & 0x80) p += 3 * (1 << ((flags & 7) + 1));
  const frames = [];
  const delays = [];
  for (;;) {
    const kind = u8();
    if (kind === 0x3b) break;
    if (kind === 0x21) {
      const label = u8();
      if (label === 0xf9) {
        u8();
        u8();
        delays.push(u16());
        p += 2;
      } else {
        for (let len = u8(); len; len = u8()) p += len;
      }
      continue;
    }
    assert.equal(kind, 0x2c, `block 0x${kind.toString(16)} at ${p - 1}`);
    p += 4;
    assert.equal(u16(), width);
    assert.equal(u16(), height);
    assert.equal(u8() & 0x80, 0, "no local colour table");
    const minSize = u8();
    const chunks = [];
    for (let len = u8(); len; len = u8()) {
      chunks.push(bytes.subarray(p, p + len));
      p += len;
    }
    const data = new Uint8Array(chunks.reduce((a, c) => a + c.length, 0));
    let o = 0;
    for (const c of chunks) {
      data.set(c, o);
      o += c.length;
    }
    frames.push(lzwDecode(data, minSize, width * height));
  }
  return { width, height, frames, delays };
}

function rgbaFrame(w, h, pixel) {
  const rgba = new Uint8ClampedArray(w * h * 4);
  for (let i = 0; i < w * h; i++) {
    const [r, g, b] = pixel(i % w, Math.floor(i / w), i);
    rgba.set([r, g, b, 255], 4 * i);
  }
  return rgba;
}

test("frames decode to exactly the quantized pixels", async () => {
  const w = 97;
  const h = 61;
  let seed = 12345;
  const rand = () => {
    seed = (seed * 1103515245 + 12345) & 0x7fffffff;
    return seed & 255;
  };
  const frames = [
    rgbaFrame(w, h, () => [rand(), rand(), rand()]), // noise: table resets
    rgbaFrame(w, h, (x, y) => [(x * 255) / w, (y * 255) / h, 128]), // gradients
    rgbaFrame(w, h, () => [255, 255, 255]), // one colour: long codes
    rgbaFrame(w, h, (x, y) => ((x - 48) ** 2 + (y - 30) ** 2 < 400 ? [59, 125, 216] : [255, 255, 255])),
  ];
  const blob = encodeGif(w, h, frames, 1000 / 24);
  const gif = decodeGif(new Uint8Array(await blob.arrayBuffer()));
  assert.equal(gif.width, w);
  assert.equal(gif.height, h);
  assert.equal(gif.frames.length, frames.length);
  assert.deepEqual(gif.delays, [4, 4, 4, 4]);
  frames.forEach((rgba, i) => assert.deepEqual(gif.frames[i], quantize(rgba), `frame ${i}`));
});

test("every length of random pixels round-trips (code width at the end code)", async () => {
  let seed = 7;
  const rand = () => {
    seed = (seed * 1103515245 + 12345) & 0x7fffffff;
    return (seed >> 8) & 255;
  };
  for (let w = 1; w <= 700; w++) {
    const rgba = rgbaFrame(w, 1, () => [rand(), rand(), rand()]);
    const gif = decodeGif(new Uint8Array(await encodeGif(w, 1, [rgba], 40).arrayBuffer()));
    assert.deepEqual(gif.frames[0], quantize(rgba), `width ${w}`);
  }
});

test("quantize maps white, black and the fill colour to the nearest palette entries", () => {
  const idx = quantize(new Uint8ClampedArray([255, 255, 255, 255, 0, 0, 0, 255, 59, 125, 216, 255]));
  assert.equal(idx[0], 251); // last entry of the 6×7×6 cube
  assert.equal(idx[1], 0);
  assert.notEqual(idx[2], idx[0]);
});
