// SPDX-License-Identifier: BSD-3-Clause
// The surfaces the server makes come to the page as binary little-endian PLY (vertex x, y, z;
// faces as index lists): read here into what the viewer draws.

// A binary little-endian PLY: float32 points and triangles (polygons fanned).
export function parsePLY(buffer) {
  const bytes = new Uint8Array(buffer);
  const text = new TextDecoder("latin1").decode(bytes.subarray(0, Math.min(bytes.length, 4096)));
  const end = text.indexOf("end_header\n");
  if (!text.startsWith("ply") || end < 0 || !text.includes("format binary_little_endian")) {
    throw new Error("not a binary little-endian PLY file");
  }
  const sizes = { char: 1, uchar: 1, int8: 1, uint8: 1, short: 2, ushort: 2, int16: 2, uint16: 2,
    int: 4, uint: 4, int32: 4, uint32: 4, float: 4, float32: 4, double: 8, float64: 8 };
  const elements = [];
  for (const line of text.substring(0, end).split("\n")) {
    const w = line.trim().split(/\s+/);
    if (w[0] === "element") {
      elements.push({ name: w[1], count: Number(w[2]), properties: [] });
    } else if (w[0] === "property") {
      elements[elements.length - 1].properties.push(w[1] === "list"
        ? { list: true, countType: w[2], type: w[3], name: w[4] } : { type: w[1], name: w[2] });
    }
  }
  const view = new DataView(buffer, end + "end_header\n".length);
  let at = 0;
  const read = (type) => {
    let v;
    switch (type) {
      case "char": case "int8": v = view.getInt8(at); break;
      case "uchar": case "uint8": v = view.getUint8(at); break;
      case "short": case "int16": v = view.getInt16(at, true); break;
      case "ushort": case "uint16": v = view.getUint16(at, true); break;
      case "int": case "int32": v = view.getInt32(at, true); break;
      case "uint": case "uint32": v = view.getUint32(at, true); break;
      case "float": case "float32": v = view.getFloat32(at, true); break;
      default: v = view.getFloat64(at, true);
    }
    at += sizes[type];
    return v;
  };
  let points = new Float32Array(0);
  const triangles = [];
  for (const e of elements) {
    if (e.name === "vertex") {
      points = new Float32Array(3 * e.count);
      const axis = { x: 0, y: 1, z: 2 };
      for (let i = 0; i < e.count; ++i) {
        for (const p of e.properties) {
          const v = read(p.type);
          if (p.name in axis) {
            points[3 * i + axis[p.name]] = v;
          }
        }
      }
    } else {
      for (let i = 0; i < e.count; ++i) {
        for (const p of e.properties) {
          if (!p.list) {
            read(p.type);
            continue;
          }
          const n = read(p.countType);
          const ids = [];
          for (let k = 0; k < n; ++k) {
            ids.push(read(p.type));
          }
          if (e.name === "face") {
            for (let k = 1; k + 1 < n; ++k) {
              triangles.push(ids[0], ids[k], ids[k + 1]);
            }
          }
        }
      }
    }
  }
  return { points, triangles: Uint32Array.from(triangles) };
}
