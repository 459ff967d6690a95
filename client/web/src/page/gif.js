// Animated GIF (GIF89a) encoder for the page's own canvas frames: a fixed 6×7×6 colour cube
// palette (252 colours, nearest colour per pixel, no dithering), LZW with 8-bit minimum code
// size, one Graphic Control Extension per frame, looping forever (NETSCAPE2.0).

const LEVELS = [6, 7, 6];

function palette() {
  const p = new Uint8Array(256 * 3);
  let i = 0;
  for (let r = 0; r < LEVELS[0]; r++) {
    for (let g = 0; g < LEVELS[1]; g++) {
      for (let b = 0; b < LEVELS[2]; b++) {
        p[i++] = Math.round((r * 255) / (LEVELS[0] - 1));
        p[i++] = Math.round((g * 255) / (LEVELS[1] - 1));
        p[i++] = Math.round((b * 255) / (LEVELS[2] - 1));
      }
    }
  }
  return p;
}

// RGBA bytes -> palette indices.
export function quantize(rgba) {
  const out = new Uint8Array(rgba.length / 4);
  for (let i = 0, j = 0; j < out.length; i += 4, j++) {
    const r = Math.round((rgba[i] * (LEVELS[0] - 1)) / 255);
    const g = Math.round((rgba[i + 1] * (LEVELS[1] - 1)) / 255);
    const b = Math.round((rgba[i + 2] * (LEVELS[2] - 1)) / 255);
    out[j] = (r * LEVELS[1] + g) * LEVELS[2] + b;
  }
  return out;
}

class ByteWriter {
  constructor() {
    this.chunks = [];
    this.buf = new Uint8Array(1 << 16);
    this.n = 0;
  }
  byte(b) {
    if (this.n === this.buf.length) {
      this.chunks.push(this.buf);
      this.buf = new Uint8Array(1 << 16);
      this.n = 0;
    }
    this.buf[this.n++] = b;
  }
  bytes(arr) {
    for (const b of arr) this.byte(b);
  }
  u16(v) {
    this.byte(v & 0xff);
    this.byte((v >> 8) & 0xff);
  }
  ascii(s) {
    for (const c of s) this.byte(c.charCodeAt(0));
  }
  result() {
    return new Blob([...this.chunks, this.buf.subarray(0, this.n)], { type: "image/gif" });
  }
}

// LZW-compresses palette indices into GIF data sub-blocks (min code size 8).
function writeLzw(w, indices) {
  const clear = 256;
  const eoi = 257;
  let size = 9;
  let nextCode = 258;
  let dict = new Map();
  const block = [];
  let acc = 0;
  let bits = 0;
  const flushBlock = () => {
    w.byte(block.length);
    w.bytes(block);
    block.length = 0;
  };
  const emit = (code) => {
    acc |= code << bits;
    bits += size;
    while (bits >= 8) {
      block.push(acc & 0xff);
      if (block.length === 255) flushBlock();
      acc >>>= 8;
      bits -= 8;
    }
  };
  w.byte(8);
  emit(clear);
  let prefix = indices[0];
  for (let i = 1; i < indices.length; i++) {
    const k = indices[i];
    const key = prefix * 256 + k;
    const code = dict.get(key);
    if (code !== undefined) {
      prefix = code;
      continue;
    }
    emit(prefix);
    if (nextCode < 4096) {
      dict.set(key, nextCode++);
      // The decoder adds its entry one code later, so it widens when nextCode - 1 == 2^size.
      if (nextCode > 1 << size && size < 12) size++;
    } else {
      emit(clear);
      dict = new Map();
      size = 9;
      nextCode = 258;
    }
    prefix = k;
  }
  emit(prefix);
  if (nextCode >= 1 << size && size < 12) size++;
  emit(eoi);
  if (bits > 0) block.push(acc & 0xff);
  if (block.length > 0) flushBlock();
  w.byte(0);
}

// frames: array of RGBA Uint8ClampedArray (width*height*4 each). delayMs per frame.
export function encodeGif(width, height, frames, delayMs) {
  const w = new ByteWriter();
  w.ascii("GIF89a");
  w.u16(width);
  w.u16(height);
  w.byte(0xf7); // global colour table, 8 bits colour resolution, 256 entries
  w.byte(0);
  w.byte(0);
  w.bytes(palette());
  w.byte(0x21);
  w.byte(0xff);
  w.byte(11);
  w.ascii("NETSCAPE2.0");
  w.bytes([3, 1, 0, 0, 0]); // loop forever
  const delay = Math.max(2, Math.round(delayMs / 10));
  for (const rgba of frames) {
    w.bytes([0x21, 0xf9, 4, 0x04]); // graphic control: do not dispose, no transparency
    w.u16(delay);
    w.bytes([0, 0]);
    w.byte(0x2c);
    w.u16(0);
    w.u16(0);
    w.u16(width);
    w.u16(height);
    w.byte(0);
    writeLzw(w, quantize(rgba));
  }
  w.byte(0x3b);
  return w.result();
}
