// The WebAssembly module under Node, against the native CLI built from the same sources: the cells
// the page presets, volumes read (raw and gzip, through the portable inflater) and extracted.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import os from 'node:os';
import zlib from 'node:zlib';
import { loadNode } from './load-node.mjs';
import { WEB, ROOT, CLI, SHARED, BUCKY, cliExtract, cliCounts } from './common.mjs';
import { SUBCASE_CELLS, APPENDIX_A, FIG9_CASE6, FIG8_SEED } from '../src/presets.js';
import { generator, randomValues, neighbouringTunnels, TUNNEL_SUBCASES } from '../src/search.js';

const cmc33 = await loadNode(WEB);

function read(file) {
  return cmc33.Volume.read(fs.readFileSync(file), path.basename(file), {});
}

function wasmCounts(volume, iso, method) {
  const mesh = volume.extract(iso, method);
  try {
    const t = mesh.topology();
    return { vertices: mesh.vertexCount(), triangles: mesh.triangleCount(), euler: t.euler, b0: t.b0, b1: t.b1, b2: t.b2, boundaryLoops: t.boundaryLoops, nonManifoldEdges: t.nonManifoldEdges };
  } finally {
    mesh.delete();
  }
}

test('the methods are the library\'s, and the CLI accepts each', () => {
  const methods = cmc33.methods();
  for (const m of ['cmc33', 'mc33-lewiner', 'mc']) assert.ok(methods.includes(m), m);
  const help = execFileSync(CLI, ['extract', '--help'], { encoding: 'utf8' });
  for (const m of methods) assert.ok(help.includes(m), `cmc33 extract --help names ${m}`);
});

test('Appendix A: 13.5.2 with cmc33, 13.5.1 with mc33-lewiner, with the paper\'s numbers', () => {
  const values = new Float64Array(APPENDIX_A);
  const right = cmc33.analyzeCell(values, 0, 'cmc33');
  assert.equal(right.subcase, '13.5.2');
  assert.equal(right.baseCase, 13);
  assert.ok(right.interior.t1 > 0 && right.interior.t2 < 1);
  const legacy = cmc33.analyzeCell(values, 0, 'mc33-lewiner');
  assert.equal(legacy.subcase, '13.5.1');
  assert.ok(Math.abs(legacy.interior.a - 0.3295) < 1e-4, `a = ${legacy.interior.a}`);
  assert.ok(Math.abs(legacy.interior.tAlt - 0.1755) < 1e-4, `t_alt = ${legacy.interior.tAlt}`);
  assert.ok(Math.abs(legacy.interior.fTAlt + 0.00073) < 1e-5, `F(t_alt) = ${legacy.interior.fTAlt}`);
});

test('every subcase preset is classified as its subcase', () => {
  assert.equal(SUBCASE_CELLS.length, 33);
  assert.deepEqual(SUBCASE_CELLS.map((c) => c.name), cmc33.subcaseNames());
  for (const cell of SUBCASE_CELLS) assert.equal(cmc33.analyzeCell(new Float64Array(cell.values), 0, 'cmc33').subcase, cell.name);
});

test('the Fig. 9 preset is a tunnel that t_alt misses', () => {
  const right = cmc33.analyzeCell(new Float64Array(FIG9_CASE6), 0, 'cmc33');
  const legacy = cmc33.analyzeCell(new Float64Array(FIG9_CASE6), 0, 'mc33-lewiner');
  assert.equal(right.subcase, '6.1.2');
  assert.equal(legacy.subcase, '6.1.1');
  const i = legacy.interior;
  assert.ok(i.tAlt < i.t1 || i.tAlt > i.t2, `t_alt ${i.tAlt} outside (${i.t1}, ${i.t2})`);
  assert.ok(i.fTAlt < 0 && right.interior.fTMax > 0);
});

test('the Fig. 8 field has two neighbouring tunnels, and cmc33 meets its field topology', () => {
  const field = randomValues(generator(FIG8_SEED), 125);
  const pairs = neighbouringTunnels(cmc33, field, 5, 0, 'cmc33');
  assert.ok(pairs.length > 0);
  for (const p of pairs) for (const s of p.subcases) assert.ok(TUNNEL_SUBCASES.has(s));
  const volume = cmc33.Volume.fromValues(field, 5, 5, 5);
  const expected = volume.fieldTopology(0);
  const got = wasmCounts(volume, 0, 'cmc33');
  volume.delete();
  assert.ok(expected.determined);
  assert.deepEqual([got.euler, got.b0, got.b1, got.b2, got.boundaryLoops], [expected.euler, expected.b0, expected.b1, expected.b2, expected.boundaryLoops]);
});

test('the sweep of the interior test is the report\'s F(t)', () => {
  const r = cmc33.analyzeCell(new Float64Array(APPENDIX_A), 0, 'cmc33').interior;
  const s = cmc33.sweep(new Float64Array(APPENDIX_A), 0, r.axis, r.cornerA, 100);
  for (let k = 0; k <= 100; ++k) {
    const t = k / 100;
    assert.ok(Math.abs(s.F[k] - (r.a * t * t + r.b * t + r.c)) < 1e-12);
  }
});

test('Bucky: every method gives the CLI\'s mesh counts and topology', () => {
  const volume = read(BUCKY);
  for (const method of cmc33.methods()) {
    for (const iso of [60, 100, 100.5]) assert.deepEqual(wasmCounts(volume, iso, method), cliCounts(cliExtract(BUCKY, iso, method)), `${method} at ${iso}`);
  }
  volume.delete();
});

test('gzip and MetaImage files read without zlib give the CLI\'s meshes', () => {
  const files = ['fuzz/corpus/nrrd/u16_le_gzip.nrrd', 'fuzz/corpus/nrrd/i16_be_gzip_skip.nrrd', 'fuzz/corpus/mha/u8_gzip.mha', 'fuzz/corpus/mha/u16_zlib_size.mha'].map((f) => path.join(ROOT, f));
  for (const file of files) {
    const volume = read(file);
    const { min, max } = volume.histogram(4);
    const iso = (min + max) / 2 + 0.25;
    assert.deepEqual(wasmCounts(volume, iso, 'cmc33'), cliCounts(cliExtract(file, iso, 'cmc33')), file);
    volume.delete();
  }
});

test("Bucky written gzip-encoded (by Node's zlib, in two members) gives the raw file's mesh", () => {
  const bytes = fs.readFileSync(BUCKY);
  const payload = bytes.subarray(bytes.indexOf('\n\n') + 2);
  assert.equal(payload.length, 32 ** 3);
  const half = payload.length / 2;
  const packed = Buffer.concat([zlib.gzipSync(payload.subarray(0, half), { level: 9 }), zlib.gzipSync(payload.subarray(half), { level: 1 })]);
  const file = path.join(fs.mkdtempSync(path.join(os.tmpdir(), 'cmc33-gzip-')), 'bucky_gzip.nrrd');
  fs.writeFileSync(file, Buffer.concat([Buffer.from('NRRD0004\ntype: uint8\ndimension: 3\nsizes: 32 32 32\nencoding: gzip\n\n'), packed]));
  const volume = read(file);
  const got = wasmCounts(volume, 100, 'cmc33');
  volume.delete();
  assert.ok(got.triangles > 10000);
  assert.deepEqual(got, cliCounts(cliExtract(file, 100, 'cmc33')));
  assert.deepEqual(got, cliCounts(cliExtract(BUCKY, 100, 'cmc33')));
  fs.rmSync(path.dirname(file), { recursive: true });
});

test('a real gzip volume (CThead) gives the CLI\'s mesh', { skip: !fs.existsSync(SHARED) && 'no ../shared/data/volumes' }, () => {
  const file = path.join(SHARED, 'CThead_256x256x113_uint16.nrrd');
  const volume = read(file);
  assert.deepEqual(wasmCounts(volume, 650.5, 'cmc33'), cliCounts(cliExtract(file, 650.5, 'cmc33')));
  volume.delete();
});

test('errors arrive as JavaScript Errors with the library\'s one-line message', () => {
  assert.throws(() => cmc33.Volume.read(new Uint8Array([1, 2, 3]), 'junk.nrrd', {}), /^Error: junk\.nrrd: not a NRRD file/);
  assert.throws(() => cmc33.analyzeCell(new Float64Array([0, 1, 2]), 0, 'cmc33'), /8 corner values/);
  assert.throws(() => cmc33.analyzeCell(new Float64Array(8), 0, 'nonsense'), /unknown method 'nonsense'/);
  const cut = fs.readFileSync(BUCKY).subarray(0, 5000);
  assert.throws(() => cmc33.Volume.read(cut, 'cut.nrrd', {}), /cut\.nrrd: /);
});

/** The vertices of `cmc33 extract FILE --iso ISO --ascii` (x y z per vertex), from the CLI's PLY. */
function cliPositions(file, iso, extra = []) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cmc33-ply-'));
  try {
    const out = path.join(dir, 'm.ply');
    execFileSync(CLI, ['extract', file, '--iso', String(iso), '-o', out, '--ascii', '--threads', '1', '--quiet', ...extra]);
    const text = fs.readFileSync(out, 'utf8');
    const header = text.slice(0, text.indexOf('end_header\n'));
    const count = Number(/element vertex (\d+)/.exec(header)[1]);
    const lines = text.slice(header.length + 'end_header\n'.length).split('\n');
    const positions = new Float64Array(3 * count);
    for (let v = 0; v < count; ++v) lines[v].split(' ').slice(0, 3).forEach((w, a) => (positions[3 * v + a] = Number(w)));
    return positions;
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
}

test('NIfTI (.nii, .nii.gz, .hdr + .img), .npy and .vti files give the CLI\'s meshes, in the file\'s world frame', () => {
  // the fuzz corpus's seeds: one byte of the fuzz target's options (frame, array), then the file
  const seeds = fs.mkdtempSync(path.join(os.tmpdir(), 'cmc33-seeds-'));
  const corpus = (f) => {
    const file = path.join(seeds, path.basename(f));
    fs.writeFileSync(file, fs.readFileSync(path.join(ROOT, 'fuzz/corpus', f)).subarray(1));
    return file;
  };
  const cases = [
    ['nifti/n1_float32.nii'], ['nifti/n2_sform.nii'], ['nifti/n1_qform_only.nii'], ['nifti/n1_gz.nii.gz'], ['nifti/n1_scaled.nii'],
    ['nifti/n1_big_endian.nii'], ['npy/array_0_f4_C.npy'], ['npy/array_1_f8_F.npy'], ['vti/image_0_ascii.vti'],
    ['vti/image_2_binary_zlib.vti'], ['vti/image_4_appended_zlib.vti'],
  ];
  let framed = 0, triangles = 0;
  for (const [name] of cases) {
    const file = corpus(name);
    const volume = read(file);
    try {
      const { min, max } = volume.histogram(4);
      const iso = (min + max) / 2 + 0.25 * (max - min) / 7;
      assert.deepEqual(wasmCounts(volume, iso, 'cmc33'), cliCounts(cliExtract(file, iso, 'cmc33')), name);
      const mesh = volume.extract(iso, 'cmc33');
      const positions = mesh.positions().slice();
      mesh.delete();
      const want = cliPositions(file, iso);
      assert.equal(positions.length, want.length, name);
      triangles += positions.length;
      let err = 0, scale = 1;
      for (let i = 0; i < want.length; ++i) {
        err = Math.max(err, Math.abs(positions[i] - want[i]));
        scale = Math.max(scale, Math.abs(want[i]));
      }
      assert.ok(err <= 1e-6 * scale, `${name}: positions differ from the CLI's by ${err}`);
      const identity = volume.direction().every((row, r) => row.every((x, c) => x === (r === c ? 1 : 0)));
      if (!identity || volume.origin().some((x) => x !== 0)) ++framed;
    } finally {
      volume.delete();
    }
  }
  assert.ok(framed >= 3, `${framed} of the files have a frame other than the identity: the frame is applied`);
  assert.ok(triangles > 0, 'some of the meshes are not empty');
  // the page reads a NIfTI pair as the CLI does: the header, with the .img as its data file
  // (made from a single file: magic ni1, vox_offset 0, the samples after vox_offset in the .img)
  const single = fs.readFileSync(corpus('nifti/n1_float32.nii'));
  const voxOffset = single.readFloatLE(108);
  const header = Buffer.from(single.subarray(0, 348));
  header.writeFloatLE(0, 108);
  header.write('ni1\0', 344, 'latin1');
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cmc33-pair-'));
  fs.writeFileSync(path.join(dir, 'pair.hdr'), header);
  fs.writeFileSync(path.join(dir, 'pair.img'), single.subarray(voxOffset));
  const pair = cmc33.Volume.read(header, 'pair.hdr', { 'pair.img': single.subarray(voxOffset) });
  const { min, max } = pair.histogram(4);
  const iso = (min + max) / 2 + 0.01;
  assert.deepEqual(wasmCounts(pair, iso, 'cmc33'), cliCounts(cliExtract(path.join(dir, 'pair.hdr'), iso, 'cmc33')));
  const whole = read(corpus('nifti/n1_float32.nii'));
  assert.deepEqual([pair.space(), pair.origin(), pair.direction()], [whole.space(), whole.origin(), whole.direction()]);
  whole.delete();
  // and a compressed pair (.hdr.gz + .img.gz, as nibabel writes them), compressed here by Node's zlib
  const [headerGz, imageGz] = [zlib.gzipSync(header), zlib.gzipSync(single.subarray(voxOffset))];
  fs.writeFileSync(path.join(dir, 'packed.hdr.gz'), headerGz);
  fs.writeFileSync(path.join(dir, 'packed.img.gz'), imageGz);
  const packed = cmc33.Volume.read(headerGz, 'packed.hdr.gz', { 'packed.img.gz': imageGz });
  assert.deepEqual(wasmCounts(packed, iso, 'cmc33'), wasmCounts(pair, iso, 'cmc33'));
  assert.deepEqual(wasmCounts(packed, iso, 'cmc33'), cliCounts(cliExtract(path.join(dir, 'packed.hdr.gz'), iso, 'cmc33')));
  packed.delete();
  pair.delete();
  fs.rmSync(dir, { recursive: true, force: true });
  // a 4-D file needs a frame, which the page cannot choose: the library's message says so
  assert.throws(() => read(corpus('nifti/n1_4d_frame1.nii')), /n1_4d_frame1\.nii: .*frame/);
  fs.rmSync(seeds, { recursive: true, force: true });
});

test('TIFF and DICOM files get a message that the page cannot read them', () => {
  const tiff = path.join(ROOT, 'fuzz/corpus/tiff/uint8.tif');
  assert.throws(() => read(tiff), /^Error: uint8\.tif: a TIFF file, which this page cannot read: its WebAssembly build has no TIFF reader/);
  // by the mark, whatever the name
  assert.throws(() => cmc33.Volume.read(fs.readFileSync(tiff), 'slice_001', {}), /slice_001: a TIFF file, which this page cannot read/);
  const dicom = fs.readdirSync(path.join(ROOT, 'fuzz/corpus/dicom')).map((f) => path.join(ROOT, 'fuzz/corpus/dicom', f))
    .find((f) => fs.statSync(f).isFile() && fs.readFileSync(f).subarray(128, 132).toString('latin1') === 'DICM');
  assert.ok(dicom, 'a DICOM file in fuzz/corpus/dicom');
  assert.throws(() => cmc33.Volume.read(fs.readFileSync(dicom), 'IM0001', {}), /IM0001: a DICOM file, which this page cannot read: its WebAssembly build has no DICOM reader/);
});
