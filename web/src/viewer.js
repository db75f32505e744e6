// A three.js view: a scene of meshes, lines and markers, orbit controls, rendering on demand.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { fitWidth } from './plots.js';

export const COLORS = { above: 0xd9534f, below: 0x3b6fb6, surface: 0xe8b64c, truth: 0x6fbf73, extra: 0x8a4fd1, bad: 0xff1493 };

export class Viewer {
  constructor(container, { width = 640, height = 380, legend = '' } = {}) {
    this.container = container;
    // narrower on a narrow screen (a phone), keeping the shape up to a point
    const w = fitWidth(width, 56);
    height = Math.round(height * Math.max(0.7, w / width));
    width = w;
    container.style.width = `${width}px`;
    container.style.height = `${height}px`;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.renderer.setSize(width, height);
    this.renderer.setClearColor(0xffffff);
    container.append(this.renderer.domElement);
    if (legend) {
      this.legend = document.createElement('div');
      this.legend.className = 'legend';
      this.legend.textContent = legend;
      container.append(this.legend);
    }
    const hint = document.createElement('div');
    hint.className = 'hint3d';
    hint.textContent = 'drag: rotate · wheel or pinch: zoom · right-drag: pan';
    container.append(hint);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, width / height, 0.01, 1e6);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x666677, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(1, 2, 3);
    this.camera.add(sun);
    this.scene.add(this.camera);
    this.group = new THREE.Group();
    this.scene.add(this.group);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    this.fitted = false;
  }

  /** Replaces the scene's objects; keeps the camera unless `refit` (or nothing was shown yet). */
  show(objects, { refit = false } = {}) {
    for (const child of [...this.group.children]) {
      this.group.remove(child);
      child.traverse((o) => {
        o.geometry?.dispose();
        o.material?.dispose();
      });
    }
    for (const o of objects) this.group.add(o);
    if (refit || !this.fitted) this.fit();
    this.render();
  }

  fit() {
    const box = new THREE.Box3().setFromObject(this.group);
    if (box.isEmpty()) return;
    const center = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    this.lookFrom(center, size, new THREE.Vector3(0.55, -0.95, 0.75).multiplyScalar(size));
  }

  /** The camera at center + offset, looking at center, z up, clipping for a scene of `size`. */
  lookFrom(center, size, offset) {
    this.camera.position.copy(center).add(offset);
    this.camera.up.set(0, 0, 1);
    this.camera.near = size / 1000;
    this.camera.far = size * 100;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(center);
    this.controls.update();
    this.fitted = true;
  }

  /** Frames the box [min, max] (seen from the same side as fit()), filling most of the view. */
  fitBox(min, max) {
    const box = new THREE.Box3(new THREE.Vector3(...min), new THREE.Vector3(...max));
    const center = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    // far enough that the box's bounding sphere fits the narrower of the view's angles
    const half = THREE.MathUtils.degToRad(this.camera.fov / 2);
    const narrow = Math.min(half, Math.atan(Math.tan(half) * this.camera.aspect));
    const distance = (size / 2 / Math.sin(narrow)) * 0.9;
    this.lookFrom(center, size, new THREE.Vector3(0.55, -0.95, 0.75).normalize().multiplyScalar(distance));
    this.render();
  }

  /**
   * A given camera: looking at `focus` from `position`, `fov` degrees, and only what lies within
   * `slab` of the focus's distance drawn (what is in front is clipped away), as a figure's zoom.
   */
  look(focus, position, { fov = 30, slab = Infinity } = {}) {
    this.camera.position.set(...position);
    this.camera.up.set(0, 0, 1);
    this.camera.fov = fov;
    const distance = new THREE.Vector3(...position).distanceTo(new THREE.Vector3(...focus));
    this.camera.near = Number.isFinite(slab) ? Math.max(distance / 1000, distance - slab) : distance / 1000;
    this.camera.far = Number.isFinite(slab) ? distance + slab : distance * 100;
    this.camera.updateProjectionMatrix();
    this.controls.target.set(...focus);
    this.controls.update();
    this.fitted = true;
    this.render();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
  }
}

/** A triangle mesh; `colors` (3 floats a vertex) overrides `color`. */
export function surface(positions, triangles, { color = COLORS.surface, opacity = 1, colors = null, offset = [0, 0, 0] } = {}) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  if (colors) geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3));
  geometry.setIndex(new THREE.BufferAttribute(triangles, 1));
  geometry.computeVertexNormals();
  const material = new THREE.MeshPhongMaterial({
    color: colors ? 0xffffff : color,
    vertexColors: Boolean(colors),
    side: THREE.DoubleSide,
    transparent: opacity < 1,
    opacity,
    depthWrite: opacity >= 1,
    shininess: 30,
  });
  const mesh = new THREE.Mesh(geometry, material);
  mesh.position.set(...offset);
  return mesh;
}

/** The 12 edges of the box [min, max]. */
export function boxEdges(min, max, color = 0x888888) {
  const geometry = new THREE.EdgesGeometry(new THREE.BoxGeometry(max[0] - min[0], max[1] - min[1], max[2] - min[2]));
  const lines = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color }));
  lines.position.set((min[0] + max[0]) / 2, (min[1] + max[1]) / 2, (min[2] + max[2]) / 2);
  return lines;
}

/** A sphere at each point, coloured one by one. */
export function markers(points, colors, radius) {
  const group = new THREE.Group();
  const geometry = new THREE.SphereGeometry(radius, 16, 12);
  points.forEach((p, i) => {
    const m = new THREE.Mesh(geometry, new THREE.MeshPhongMaterial({ color: colors[i] }));
    m.position.set(...p);
    group.add(m);
  });
  return group;
}

/** Thick segments (thin cylinders) between pairs of points, to highlight edges. */
export function segments(pairs, color, radius) {
  const group = new THREE.Group();
  const up = new THREE.Vector3(0, 1, 0);
  for (const [a, b] of pairs) {
    const va = new THREE.Vector3(...a), vb = new THREE.Vector3(...b);
    const length = va.distanceTo(vb);
    const m = new THREE.Mesh(new THREE.CylinderGeometry(radius, radius, length, 8), new THREE.MeshBasicMaterial({ color }));
    m.position.copy(va).add(vb).multiplyScalar(0.5);
    m.quaternion.setFromUnitVectors(up, vb.clone().sub(va).normalize());
    group.add(m);
  }
  return group;
}

/** A flat, semi-transparent quad with corners p0..p3 (a cell face). */
export function quad(corners, color, opacity = 0.35) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(corners.flat()), 3));
  geometry.setIndex([0, 1, 2, 0, 2, 3]);
  return new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ color, side: THREE.DoubleSide, transparent: true, opacity, depthWrite: false }));
}

/** Moves the cameras of `viewers` together: rotating, zooming or panning one moves the others. */
export function linkCameras(viewers) {
  let syncing = false;
  for (const v of viewers) {
    v.controls.addEventListener('change', () => {
      if (syncing) return;
      syncing = true;
      for (const w of viewers) {
        if (w === v) continue;
        w.camera.position.copy(v.camera.position);
        w.camera.up.copy(v.camera.up);
        w.camera.fov = v.camera.fov;
        w.camera.near = v.camera.near;
        w.camera.far = v.camera.far;
        w.camera.updateProjectionMatrix();
        w.controls.target.copy(v.controls.target);
        w.controls.update();
        w.render();
      }
      syncing = false;
    });
  }
}
