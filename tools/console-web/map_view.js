// adit console: the live 3D view. Tiles from the console become one
// THREE.Points each, coloured by height in the shader (so every tile shares
// one colour scale that follows the map's extent without recolouring); the
// path is a line, the current pose a cone; the live 2D grid textured planes
// under the points, a block each (grid_layer.js); cameras: follow, top, free (orbit with a
// finger or the mouse, pinch or wheel to zoom). The path and the pose are in
// the session's odometry frame, the tiles and the grid in the tiles' frame
// (the odometry's, or the pose graph's when the loop closure moves the map),
// each inside a group that the payload's frame (frame_t: the prior map's once
// anchored) places in the map frame. Once a loop closed, the path up to the
// graph's newest keyframe is the graph's (graph_path_t, in the tiles' frame,
// moved with the map) and the poses' path goes on from there.
import * as THREE from '/vendor/three/three.module.js';
import { GridLayer } from './grid_layer.js';

const heightShader = {
  vertex: `
    uniform float size;
    uniform float zmin;
    uniform float zmax;
    varying vec3 vColor;
    vec3 ramp(float t) {  // blue - cyan - green - yellow - red
      t = clamp(t, 0.0, 1.0);
      return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
    }
    void main() {
      vColor = ramp((position.z - zmin) / max(zmax - zmin, 0.1));
      gl_PointSize = size;
      gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
    }`,
  fragment: `
    varying vec3 vColor;
    void main() { gl_FragColor = vec4(vColor, 1.0); }`,
};

export class MapView {
  constructor(canvas) {
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.scene = new THREE.Scene();
    this.world = new THREE.Group();  // map <- odometry (setFrame)
    this.world.matrixAutoUpdate = false;
    this.scene.add(this.world);
    this.tilesWorld = new THREE.Group();  // map <- tiles (setFrame)
    this.tilesWorld.matrixAutoUpdate = false;
    this.scene.add(this.tilesWorld);
    this.camera = new THREE.PerspectiveCamera(60, 1, 0.1, 5000);
    this.camera.up.set(0, 0, 1);  // the map frame has z up
    this.material = new THREE.ShaderMaterial({
      uniforms: { size: { value: 2.0 }, zmin: { value: -2 }, zmax: { value: 4 } },
      vertexShader: heightShader.vertex,
      fragmentShader: heightShader.fragment,
    });
    this.tiles = new Map();  // id -> { v, every, segments: [Float32Array], points: THREE.Points, n }
    this.zRange = null;
    this.pathCapacity = 1024;
    this.pathPositions = new Float32Array(this.pathCapacity * 3);
    this.pathTimes = new Float64Array(this.pathCapacity);  // each point's pose utime (µs)
    this.pathCount = 0;
    this.pathGeometry = new THREE.BufferGeometry();
    this.pathGeometry.setAttribute('position', new THREE.BufferAttribute(this.pathPositions, 3));
    this.pathGeometry.setDrawRange(0, 0);
    this.path = new THREE.Line(this.pathGeometry, new THREE.LineBasicMaterial({ color: 0xffffff }));
    this.path.frustumCulled = false;
    this.world.add(this.path);
    this.graphGeometry = new THREE.BufferGeometry();
    this.graphPath = new THREE.Line(this.graphGeometry, this.path.material);
    this.graphPath.frustumCulled = false;
    this.graphPath.visible = false;
    this.tilesWorld.add(this.graphPath);
    this.graphTime = -Infinity;  // the graph path's newest keyframe (µs): the poses' path starts there
    const cone = new THREE.ConeBufferGeometry(0.5, 1.6, 12);
    cone.rotateZ(-Math.PI / 2);  // the cone points along the body's x axis
    this.marker = new THREE.Mesh(cone, new THREE.MeshBasicMaterial({ color: 0xff2bd6 }));
    this.marker.visible = false;
    this.world.add(this.marker);
    this.grid = new GridLayer(this.tilesWorld);
    this.mode = 'follow';
    this.orbit = { target: new THREE.Vector3(), distance: 40, azimuth: -Math.PI / 2, elevation: 0.9 };
    this.poseDirty = false;
    this.dirty = true;         // something changed since the last frame: draw one (a still map costs nothing)
    this.continuous = false;   // draw every animation frame (the frame-rate measurement)
    this.onFrame = null;  // called after each render with (now, poseDrawn)
    this.setTheme(false);
    this.bindPointer();
    this.resize();
    window.addEventListener('resize', () => this.resize());
    const loop = () => {
      if (this.dirty || this.continuous) this.render();
      requestAnimationFrame(loop);
    };
    requestAnimationFrame(loop);
  }

  setTheme(sun) {
    this.renderer.setClearColor(sun ? 0xffffff : 0x0a0d10);
    this.path.material.color.set(sun ? 0x000000 : 0xffffff);
    if (this.grid) this.grid.setTheme(sun);
    this.dirty = true;
  }

  resize() {
    const w = this.canvas.clientWidth || 1, h = this.canvas.clientHeight || 1;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  clear() {
    for (const t of this.tiles.values()) this.dropTile(t);
    this.tiles.clear();
    this.zRange = null;
    this.pathCount = 0;
    this.pathGeometry.setDrawRange(0, 0);
    this.graphPath.visible = false;
    this.graphTime = -Infinity;
    this.marker.visible = false;
    this.grid.clear();
    this.setFrame(null);
    this.dirty = true;
  }

  // Where the odometry frame and the tiles' frame lie in the map frame
  // ({p, q: map <- odometry, tp, tq: map <- tiles; p [x y z], q [w x y z]}, or null: identity).
  setFrame(frame) {
    const place = (group, p, q) => {
      if (p && q) {
        const r = new THREE.Quaternion(q[1], q[2], q[3], q[0]);  // three.js: x y z w
        group.matrix.compose(new THREE.Vector3(p[0], p[1], p[2]), r, new THREE.Vector3(1, 1, 1));
      } else {
        group.matrix.identity();
      }
      group.matrixWorldNeedsUpdate = true;
    };
    place(this.world, frame && frame.p, frame && frame.q);
    place(this.tilesWorld, frame && (frame.tp || frame.p), frame && (frame.tq || frame.q));
    this.dirty = true;
  }

  // The pose marker in the map frame.
  markerPosition() { this.world.updateMatrixWorld(); return this.marker.getWorldPosition(new THREE.Vector3()); }
  markerQuaternion() { this.world.updateMatrixWorld(); return this.marker.getWorldQuaternion(new THREE.Quaternion()); }

  // The live 2D grid's blocks and their list (grid_layer.js), and whether it shows.
  setGridBlock(block) {
    this.grid.setBlock(block);
    this.dirty = true;
  }
  setGridIndex(index) {
    this.grid.setIndex(index);
    this.dirty = true;
  }
  gridBlockVersion(x, y) { return this.grid.blockVersion(x, y); }
  gridVersion() { return this.grid.version(); }
  showGrid(on) {
    this.grid.setVisible(on);
    this.dirty = true;
  }

  dropTile(t) {
    if (t.points) {
      this.tilesWorld.remove(t.points);
      t.points.geometry.dispose();
    }
  }

  tileVersion(id) { const t = this.tiles.get(id); return t ? t.v : 0; }
  tileEvery(id) { const t = this.tiles.get(id); return t ? t.every : 0; }
  pointCount() { let n = 0; for (const t of this.tiles.values()) n += t.n; return n; }

  // Segments `from`.. of tile `id` at version `v` (each a Float32Array of x y z), `nSegments` in all.
  setTile(id, v, every, from, nSegments, segments) {
    let t = this.tiles.get(id);
    if (!t || t.every !== every) {
      if (t) this.dropTile(t);
      t = { v: 0, every, segments: [], points: null, n: 0 };
      this.tiles.set(id, t);
    }
    t.segments.length = Math.min(t.segments.length, from);
    for (let i = t.segments.length; i < from; ++i) t.segments.push(new Float32Array(0));
    for (const s of segments) t.segments.push(s);
    t.segments.length = nSegments;
    t.v = v;
    let n = 0;
    for (const s of t.segments) n += s ? s.length : 0;
    const positions = new Float32Array(n);
    let at = 0;
    for (const s of t.segments) if (s) { positions.set(s, at); at += s.length; }
    for (let i = 2; i < n; i += 3) this.growZ(positions[i]);
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    geometry.computeBoundingSphere();
    if (t.points) {
      t.points.geometry.dispose();
      t.points.geometry = geometry;
    } else {
      t.points = new THREE.Points(geometry, this.material);
      this.tilesWorld.add(t.points);
    }
    t.n = n / 3;
    this.dirty = true;
  }

  growZ(z) {
    if (!this.zRange) this.zRange = [z, z];
    if (z < this.zRange[0]) this.zRange[0] = z;
    if (z > this.zRange[1]) this.zRange[1] = z;
  }

  // Points [x, y, z, utime] in the odometry frame.
  setPath(points) {
    this.pathCount = 0;
    for (const p of points) this.addPathPoint(p, p[3]);
    this.pathGeometry.setDrawRange(0, this.pathCount);
  }

  // The pose graph's path ({utime, points: [[x y z], ...]} in the tiles'
  // frame): drawn with the tiles; the poses' path before its newest keyframe goes.
  setGraphPath(g) {
    const flat = new Float32Array(g.points.length * 3);
    g.points.forEach((p, i) => flat.set(p, i * 3));
    this.graphGeometry.dispose();  // frees the last path's GPU buffer (a new one per loop closed)
    this.graphGeometry = new THREE.BufferGeometry();
    this.graphPath.geometry = this.graphGeometry;
    this.graphGeometry.setAttribute('position', new THREE.BufferAttribute(flat, 3));
    this.graphGeometry.setDrawRange(0, g.points.length);
    this.graphPath.visible = g.points.length > 1;
    this.graphTime = g.utime;
    let first = 0;
    while (first < this.pathCount && this.pathTimes[first] < g.utime) first += 1;
    if (first > 0) {
      this.pathPositions.copyWithin(0, first * 3, this.pathCount * 3);
      this.pathTimes.copyWithin(0, first, this.pathCount);
      this.pathCount -= first;
      this.pathGeometry.attributes.position.needsUpdate = true;
      this.pathGeometry.setDrawRange(0, this.pathCount);
    }
    this.dirty = true;
  }

  addPathPoint(p, t) {
    if (t < this.graphTime) return;  // the graph's path holds it
    if (this.pathCount > 0) {
      const i = (this.pathCount - 1) * 3;
      const dx = p[0] - this.pathPositions[i], dy = p[1] - this.pathPositions[i + 1], dz = p[2] - this.pathPositions[i + 2];
      if (dx * dx + dy * dy + dz * dz < 0.0025) return;
    }
    if (this.pathCount === this.pathCapacity) {
      this.pathCapacity *= 2;
      const bigger = new Float32Array(this.pathCapacity * 3);
      bigger.set(this.pathPositions);
      this.pathPositions = bigger;
      const times = new Float64Array(this.pathCapacity);
      times.set(this.pathTimes);
      this.pathTimes = times;
      this.pathGeometry.setAttribute('position', new THREE.BufferAttribute(this.pathPositions, 3));
    }
    this.pathPositions.set([p[0], p[1], p[2]], this.pathCount * 3);
    this.pathTimes[this.pathCount] = t;
    this.pathCount += 1;
    this.pathGeometry.attributes.position.needsUpdate = true;
    this.pathGeometry.setDrawRange(0, this.pathCount);
  }

  setPose(pose) {
    this.marker.position.set(pose.p[0], pose.p[1], pose.p[2]);
    this.marker.quaternion.set(pose.q[1], pose.q[2], pose.q[3], pose.q[0]);  // three.js: x y z w
    this.marker.visible = true;
    if (pose.valid) this.addPathPoint(pose.p, pose.utime);
    this.poseDirty = true;
    this.dirty = true;
  }

  setMode(mode) {
    if (mode === 'free' && this.mode !== 'free') {
      // Start orbiting from where the camera looks now.
      this.orbit.target.copy(this.marker.visible ? this.markerPosition() : new THREE.Vector3());
      const d = this.camera.position.clone().sub(this.orbit.target);
      this.orbit.distance = Math.max(d.length(), 2);
      this.orbit.azimuth = Math.atan2(d.y, d.x);
      this.orbit.elevation = Math.asin(Math.min(1, Math.max(-1, d.z / this.orbit.distance)));
    }
    this.mode = mode;
    this.dirty = true;
  }

  placeCamera() {
    const at = this.marker.visible ? this.markerPosition() : new THREE.Vector3();
    if (this.mode === 'follow') {
      const heading = new THREE.Vector3(1, 0, 0).applyQuaternion(this.markerQuaternion());
      heading.z = 0;
      if (heading.lengthSq() < 1e-6) heading.set(1, 0, 0);
      heading.normalize();
      this.camera.position.set(at.x - 12 * heading.x, at.y - 12 * heading.y, at.z + 8);
      this.camera.lookAt(at);
    } else if (this.mode === 'top') {
      this.camera.position.set(at.x, at.y - 0.01, at.z + 70);
      this.camera.lookAt(at);
    } else {
      const o = this.orbit;
      this.camera.position.set(o.target.x + o.distance * Math.cos(o.elevation) * Math.cos(o.azimuth),
                               o.target.y + o.distance * Math.cos(o.elevation) * Math.sin(o.azimuth),
                               o.target.z + o.distance * Math.sin(o.elevation));
      this.camera.lookAt(o.target);
    }
  }

  render() {
    this.dirty = false;
    if (this.zRange) {
      this.material.uniforms.zmin.value = this.zRange[0];
      this.material.uniforms.zmax.value = this.zRange[1];
    }
    this.grid.setFloor(this.zRange ? this.zRange[0] : 0);
    // From above, the grid (and the path and pose on it) over the points: the roof would hide them.
    const overlay = this.mode === 'top' && this.grid.visible && this.grid.version() > 0;
    this.grid.setOnTop(overlay);
    for (const o of [this.path, this.graphPath, this.marker]) {
      o.material.depthTest = !overlay;
      o.renderOrder = overlay ? 2 : 0;
    }
    this.placeCamera();
    this.renderer.render(this.scene, this.camera);
    const poseDrawn = this.poseDirty;
    this.poseDirty = false;
    if (this.onFrame) this.onFrame(performance.now(), poseDrawn);
  }

  // Free camera: one pointer turns, two pinch (zoom) and move together (pan); the wheel zooms.
  bindPointer() {
    const pointers = new Map();
    let last = null;
    const spread = () => { const [a, b] = [...pointers.values()]; return Math.hypot(a.x - b.x, a.y - b.y); };
    const centre = () => { const [a, b] = [...pointers.values()]; return { x: (a.x + b.x) / 2, y: (a.y + b.y) / 2 }; };
    this.canvas.addEventListener('pointerdown', (e) => {
      this.canvas.setPointerCapture(e.pointerId);
      pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
      if (this.mode !== 'free') this.setMode('free'), this.onModeChange && this.onModeChange('free');
      last = pointers.size === 2 ? { spread: spread(), centre: centre() } : { x: e.clientX, y: e.clientY };
    });
    this.canvas.addEventListener('pointermove', (e) => {
      if (!pointers.has(e.pointerId)) return;
      pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
      this.dirty = true;
      const o = this.orbit;
      if (pointers.size === 1 && last && last.x !== undefined) {
        o.azimuth -= (e.clientX - last.x) * 0.008;
        o.elevation = Math.min(1.55, Math.max(-0.2, o.elevation + (e.clientY - last.y) * 0.008));
        last = { x: e.clientX, y: e.clientY };
      } else if (pointers.size === 2 && last && last.spread) {
        const s = spread(), c = centre();
        o.distance = Math.min(3000, Math.max(1, o.distance * last.spread / Math.max(s, 1)));
        const k = o.distance * 0.002;
        const right = new THREE.Vector3(-Math.sin(o.azimuth), Math.cos(o.azimuth), 0);
        const forward = new THREE.Vector3(-Math.cos(o.azimuth), -Math.sin(o.azimuth), 0);
        o.target.addScaledVector(right, -(c.x - last.centre.x) * k).addScaledVector(forward, (c.y - last.centre.y) * k);
        last = { spread: s, centre: c };
      }
    });
    const up = (e) => { pointers.delete(e.pointerId); last = null; };
    this.canvas.addEventListener('pointerup', up);
    this.canvas.addEventListener('pointercancel', up);
    this.canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      if (this.mode !== 'free') this.setMode('free'), this.onModeChange && this.onModeChange('free');
      this.orbit.distance = Math.min(3000, Math.max(1, this.orbit.distance * Math.exp(e.deltaY * 0.001)));
      this.dirty = true;
    }, { passive: false });
  }
}
