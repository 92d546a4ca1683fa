// The 3-D scene with three.js (vendored in /vendor/three, no CDN): solids see-through or coloured
// per vertex (a GLB mesh), paths, the tool (ball, neck, shank) at a cursor, a mm grid and axes,
// view presets and zoom to fit.
import * as THREE from 'three';
import { OrbitControls } from '/vendor/three/OrbitControls.js';

// Grid spacing in mm for a scene `extent` mm across: 1, 2 or 5 times a power of ten, about 20 lines.
function gridStep(extent) {
  const raw = extent / 20;
  const power = 10 ** Math.floor(Math.log10(raw));
  return [1, 2, 5, 10].map((m) => m * power).find((s) => s >= raw);
}

function vector(p) {
  return new THREE.Vector3(p[0], p[1], p[2] ?? 0);
}

// Whether this browser can draw WebGL (a headless or locked-down browser may not).
function webglAvailable() {
  try {
    const canvas = document.createElement('canvas');
    return Boolean(canvas.getContext('webgl2') || canvas.getContext('webgl'));
  } catch (error) {
    return false;
  }
}

// Reads a binary glTF (GLB) of one indexed triangle mesh as `POST /api/v1/verify?format=glb`
// answers it (docs/spec/verify.md §8): the 12-byte header, the JSON chunk and the binary chunk.
// Gives the glTF JSON and a BufferGeometry with `position`, `normal`, `color` (COLOR_0) and
// `deviation` (_DEVIATION, when the request had a part); `geometry` is null for an empty mesh.
export function readGlb(buffer) {
  const view = new DataView(buffer);
  if (buffer.byteLength < 20 || view.getUint32(0, true) !== 0x46546c67 || view.getUint32(4, true) !== 2) {
    throw new Error('not a glTF 2.0 binary');
  }
  const jsonLength = view.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 20, jsonLength)));
  const primitive = json.meshes?.[0]?.primitives?.[0];
  if (!primitive) return { json, geometry: null };
  const binary = 20 + jsonLength + 8;
  const attribute = (index) => {
    const accessor = json.accessors[index];
    const bufferView = json.bufferViews[accessor.bufferView];
    const size = { SCALAR: 1, VEC3: 3, VEC4: 4 }[accessor.type];
    const Type = { 5126: Float32Array, 5125: Uint32Array, 5121: Uint8Array }[accessor.componentType];
    const values = new Type(buffer, binary + (bufferView.byteOffset ?? 0) + (accessor.byteOffset ?? 0), accessor.count * size);
    return new THREE.BufferAttribute(values, size, Boolean(accessor.normalized));
  };
  const geometry = new THREE.BufferGeometry();
  const names = { POSITION: 'position', NORMAL: 'normal', COLOR_0: 'color', _DEVIATION: 'deviation' };
  for (const [name, index] of Object.entries(primitive.attributes)) {
    if (names[name]) geometry.setAttribute(names[name], attribute(index));
  }
  geometry.setIndex(attribute(primitive.indices));
  return { json, geometry };
}

// A 3-D scene in `container`: a toolbar (view presets, zoom to fit), the WebGL canvas (drag to
// rotate, right-drag to pan, wheel to zoom; focused, the arrow keys rotate and +/- zoom) and a
// legend. Machine Z is up. `presets` adds named view directions, e.g. {label: 'Along hole axis',
// direction: [x, y, z]} (the direction the camera looks from).
export class Scene3D {
  constructor(container, { label, presets = [] } = {}) {
    this.root = document.createElement('div');
    this.root.className = 'scene';
    this.root.setAttribute('role', 'group');
    this.root.setAttribute('aria-label', label);
    container.append(this.root);
    this.names = [];
    this.segments = 0;
    this.box = new THREE.Box3();
    if (!webglAvailable()) {
      this.root.dataset.state = 'no-webgl';
      this.root.append(Object.assign(document.createElement('p'), { className: 'message warning', textContent: 'This browser cannot draw 3-D (WebGL is off). The numbers and the G-code are unaffected.' }));
      return;
    }
    const bar = document.createElement('div');
    bar.className = 'scene-bar';
    const views = [
      { label: 'Top', direction: [0, 0, 1] },
      { label: 'Front', direction: [0, -1, 0] },
      { label: 'Iso', direction: [1, -1.2, 0.9] },
      ...presets,
    ];
    for (const preset of views) {
      const button = document.createElement('button');
      button.type = 'button';
      button.className = 'secondary small';
      button.textContent = preset.label;
      button.addEventListener('click', () => this.look(preset.direction));
      bar.append(button);
    }
    const fit = document.createElement('button');
    fit.type = 'button';
    fit.className = 'secondary small';
    fit.textContent = 'Zoom to fit';
    fit.addEventListener('click', () => this.fit());
    bar.append(fit);
    this.legend = document.createElement('ul');
    this.legend.className = 'legend';
    this.root.append(bar);

    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(0xffffff);
    this.canvas = this.renderer.domElement;
    this.canvas.className = 'plot';
    this.canvas.tabIndex = 0;
    this.canvas.setAttribute('role', 'img');
    this.canvas.setAttribute('aria-label', `${label}. Arrow keys rotate, + and − zoom.`);
    this.root.append(this.canvas, this.legend);
    this.scene = new THREE.Scene();
    this.scene.add(new THREE.AmbientLight(0xffffff, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 2);
    sun.position.set(1, -2, 3);
    this.scene.add(sun);
    this.camera = new THREE.OrthographicCamera(-1, 1, 1, -1, -1e5, 1e5);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.addEventListener('change', () => this.render());
    this.canvas.addEventListener('keydown', (e) => this.key(e));
    this.canvas.addEventListener('dblclick', () => this.fit());
    this.resize = new ResizeObserver(() => this.render());
    this.resize.observe(this.canvas);
    this.direction = views[2].direction;
  }

  // Names of what the scene shows, for tests and assistive text.
  note(name, legend, colour) {
    if (!this.names.includes(name)) this.names.push(name);
    this.root.dataset.objects = this.names.join(' ');
    if (legend) {
      const item = document.createElement('li');
      const swatch = document.createElement('span');
      swatch.className = 'swatch';
      swatch.style.background = colour;
      item.append(swatch, legend);
      this.legend.append(item);
    }
  }

  add(name, object, legend, colour) {
    if (!this.scene) return null;
    object.name = name;
    this.scene.add(object);
    if (!name.startsWith('tool')) this.box.expandByObject(object);
    this.note(name, legend, colour);
    return object;
  }

  // A see-through solid (BufferGeometry in machine coordinates, or with `matrix`).
  solid(name, geometry, { colour = '#8fa3b5', opacity = 0.25, legend, matrix, edges = true } = {}) {
    if (!this.scene) return null;
    const mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({
      color: colour, transparent: true, opacity, side: THREE.DoubleSide, depthWrite: false,
    }));
    if (matrix) mesh.applyMatrix4(matrix);
    if (edges) mesh.add(new THREE.LineSegments(new THREE.EdgesGeometry(geometry, 30), new THREE.LineBasicMaterial({ color: colour, transparent: true, opacity: Math.min(1, opacity * 2.5) })));
    return this.add(name, mesh, legend, colour);
  }

  // An opaque solid coloured per vertex (its `color` attribute), e.g. the cut stock of a GLB
  // answer; it replaces the object of the same `name`, so playback can swap it step by step.
  coloured(name, geometry, { legend, colour } = {}) {
    if (!this.scene) return null;
    const old = this.scene.getObjectByName(name);
    if (old) {
      this.scene.remove(old);
      old.geometry.dispose();
      old.material.dispose();
    }
    const mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({ vertexColors: true }));
    return this.add(name, mesh, old ? undefined : legend, colour);
  }

  // A polyline; `colours` (one CSS colour per point) colours each segment by its end point;
  // `arrows` (a spacing in mm) adds cones pointing the way the path runs.
  path(name, points, { colour = '#0b63b6', colours, dashed = false, legend, arrows } = {}) {
    if (!this.scene || points.length < 2) return null;
    const geometry = new THREE.BufferGeometry().setFromPoints(points.map(vector));
    let material;
    if (colours) {
      geometry.setAttribute('color', new THREE.Float32BufferAttribute(colours.flatMap((c) => new THREE.Color(c).toArray()), 3));
      material = new THREE.LineBasicMaterial({ vertexColors: true });
    } else if (dashed) {
      material = new THREE.LineDashedMaterial({ color: colour, dashSize: 1, gapSize: 0.6 });
    } else {
      material = new THREE.LineBasicMaterial({ color: colour });
    }
    const line = new THREE.Line(geometry, material);
    if (dashed) line.computeLineDistances();
    if (arrows > 0) this.arrows(line, points, arrows, colour);
    this.segments += points.length - 1;
    return this.add(name, line, legend, colour);
  }

  // Cones every `spacing` mm along `points`, children of `line`.
  arrows(line, points, spacing, colour) {
    const material = new THREE.MeshLambertMaterial({ color: colour });
    const cone = new THREE.ConeGeometry(spacing / 7, spacing / 2.5, 12);
    const up = new THREE.Vector3(0, 1, 0);
    let travelled = spacing / 2;
    for (let i = 1; i < points.length; i++) {
      const [a, b] = [vector(points[i - 1]), vector(points[i])];
      const length = a.distanceTo(b);
      const direction = b.clone().sub(a).normalize();
      for (let at = spacing - travelled; at <= length; at += spacing) {
        const arrow = new THREE.Mesh(cone, material);
        arrow.position.copy(a).addScaledVector(direction, at);
        arrow.quaternion.setFromUnitVectors(up, direction);
        line.add(arrow);
      }
      travelled = (travelled + length) % spacing;
    }
  }

  // Small dots at points.
  dots(name, points, { colour = '#0b63b6', size = 4, legend } = {}) {
    if (!this.scene || !points.length) return null;
    const geometry = new THREE.BufferGeometry().setFromPoints(points.map(vector));
    return this.add(name, new THREE.Points(geometry, new THREE.PointsMaterial({ color: colour, size, sizeAttenuation: false })), legend, colour);
  }

  // The tool: a ball of `radius` (or a flat end of that radius), a neck of `neck` radius and
  // `neckLength`, a shank above, its head in `colour` (red for a refused program); `moveTool`
  // puts its ball centre (or a flat tool's tip) at a point.
  tool({ radius, kind = 'ball', neck, neckLength, shank, shankLength, colour = '#c47f17' }) {
    if (!this.scene) return;
    const group = new THREE.Group();
    // Lambert shading: cheap enough for software WebGL, which is what a PC without a GPU driver has.
    const metal = new THREE.MeshLambertMaterial({ color: colour });
    const steel = new THREE.MeshLambertMaterial({ color: '#6b7780', transparent: true, opacity: 0.85 });
    const upright = (geometry, z) => {
      geometry.rotateX(Math.PI / 2);
      geometry.translate(0, 0, z);
      return geometry;
    };
    let z = 0;
    if (kind === 'ball') {
      group.add(new THREE.Mesh(new THREE.SphereGeometry(radius, 32, 16), metal));
    } else {
      group.add(new THREE.Mesh(upright(new THREE.CylinderGeometry(radius, radius, radius, 32), radius / 2), metal));
      z = radius;
    }
    const neckRadius = neck ?? radius;
    const neckTall = neckLength ?? (neck ? 3 * radius : 0);
    if (neckTall > 0) group.add(new THREE.Mesh(upright(new THREE.CylinderGeometry(neckRadius, neckRadius, neckTall, 24), z + neckTall / 2), steel));
    const shankRadius = shank ?? radius;
    const shankTall = shankLength ?? 6 * radius;
    group.add(new THREE.Mesh(upright(new THREE.CylinderGeometry(shankRadius, shankRadius, shankTall, 24), z + neckTall + shankTall / 2), steel));
    group.visible = false;
    this.toolParts = { metal, steel, colour };
    this.toolObject = this.add('tool', group, kind === 'ball' ? 'tool (ball, neck, shank)' : 'tool', colour);
  }

  // Draws the whole tool red while it is somewhere it must not be (`hit`), else in its colours.
  markTool(hit) {
    if (!this.toolParts) return;
    const { metal, steel, colour } = this.toolParts;
    metal.color.set(hit ? '#d50000' : colour);
    steel.color.set(hit ? '#d50000' : '#6b7780');
    this.root.dataset.toolHit = String(Boolean(hit));
    this.render();
  }

  // Puts the tool's ball centre (flat: tip) at `p`, or hides it for null.
  moveTool(p) {
    if (!this.toolObject) return;
    this.toolObject.visible = Boolean(p);
    if (p) this.toolObject.position.copy(vector(p));
    this.root.dataset.tool = p ? p.map((v) => v.toFixed(3)).join(' ') : '';
    this.render();
  }

  // Adds the mm grid in the XY plane under everything and the axes, then fits. Call once the
  // scene has its objects.
  finish() {
    if (!this.scene) return;
    if (this.box.isEmpty()) this.box.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
    const size = this.box.getSize(new THREE.Vector3());
    const centre = this.box.getCenter(new THREE.Vector3());
    const extent = Math.max(size.x, size.y, size.z, 1e-6);
    const step = gridStep(extent * 1.2);
    const span = Math.ceil((Math.max(size.x, size.y) * 1.2) / step / 2) * 2 * step;
    const grid = new THREE.GridHelper(span, Math.round(span / step), 0x9aa5ae, 0xd5dbe0);
    grid.rotation.x = Math.PI / 2;
    grid.position.set(Math.round(centre.x / step) * step, Math.round(centre.y / step) * step, this.box.min.z);
    this.scene.add(grid);
    this.note('grid', `grid ${step} mm`, '#d5dbe0');
    const axes = new THREE.AxesHelper(step * 3);
    axes.position.set(grid.position.x - span / 2, grid.position.y - span / 2, this.box.min.z);
    this.scene.add(axes);
    this.note('axes', 'axes X red, Y green, Z blue', 'linear-gradient(90deg, #e53935 33%, #43a047 33% 66%, #1e63d6 66%)');
    this.root.dataset.segments = String(this.segments);
    this.look(this.direction);
    this.root.dataset.state = 'drawn';
  }

  // Looks at the scene from `direction` and zooms to fit.
  look(direction) {
    if (!this.scene) return;
    this.direction = direction;
    const d = vector(direction).normalize();
    this.camera.up.set(0, 0, 1);
    if (Math.abs(d.z) > 0.999) this.camera.up.set(0, 1, 0);
    this.fit();
  }

  fit() {
    if (!this.scene) return;
    const centre = this.box.getCenter(new THREE.Vector3());
    const radius = Math.max(this.box.getBoundingSphere(new THREE.Sphere()).radius, 1e-6);
    const d = vector(this.direction).normalize();
    this.controls.target.copy(centre);
    this.camera.position.copy(centre).addScaledVector(d, radius * 4);
    this.camera.zoom = 1;
    this.radius = radius;
    this.camera.lookAt(centre);
    this.controls.update();
    this.render();
  }

  key(event) {
    const turn = { ArrowLeft: [-0.1, 0], ArrowRight: [0.1, 0], ArrowUp: [0, -0.1], ArrowDown: [0, 0.1] }[event.key];
    if (turn) {
      const offset = this.camera.position.clone().sub(this.controls.target);
      const spherical = new THREE.Spherical().setFromVector3(new THREE.Vector3(offset.x, offset.z, -offset.y));
      spherical.theta += turn[0];
      spherical.phi = Math.max(0.01, Math.min(Math.PI - 0.01, spherical.phi + turn[1]));
      const v = new THREE.Vector3().setFromSpherical(spherical);
      this.camera.position.copy(this.controls.target).add(new THREE.Vector3(v.x, -v.z, v.y));
      this.camera.lookAt(this.controls.target);
    } else if (event.key === '+' || event.key === '=') {
      this.camera.zoom *= 1.2;
    } else if (event.key === '-') {
      this.camera.zoom /= 1.2;
    } else {
      return;
    }
    event.preventDefault();
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() {
    if (!this.renderer || !this.canvas.isConnected) return;
    const width = this.canvas.clientWidth;
    const height = this.canvas.clientHeight;
    if (!width || !height) return;
    const size = this.renderer.getSize(new THREE.Vector2());
    if (size.x !== width || size.y !== height) this.renderer.setSize(width, height, false);
    const r = (this.radius || 1) * 1.2;
    const aspect = width / height;
    Object.assign(this.camera, aspect > 1
      ? { left: -r * aspect, right: r * aspect, top: r, bottom: -r }
      : { left: -r, right: r, top: r / aspect, bottom: -r / aspect });
    this.camera.updateProjectionMatrix();
    this.renderer.render(this.scene, this.camera);
  }
}

export { THREE };
