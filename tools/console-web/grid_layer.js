// adit console: the live 2D occupancy grid under the point cloud. The console
// serves it as one PNG (GET /api/grid: grey + alpha, one pixel a cell, the
// top row the highest y; docs/CONSOLE.md). The browser decodes the PNG off
// the main thread (createImageBitmap) and the GPU takes it as it is: a
// horizontal plane in the map frame just under the lowest point, coloured in
// the shader (occupied dark, free light, unknown not drawn), so a new grid
// every second costs the page no per-cell work. Seen from above (the top
// view) a mine's roof would hide it: there it is drawn over the points.
import * as THREE from '/vendor/three/three.module.js';

// [occupied, free] per theme (RGB 0..255); unknown cells are not drawn.
const palettes = {
  dark: { occupied: [38, 44, 52], free: [112, 124, 138] },  // walls apart from the background (10, 13, 16)
  sun: { occupied: [0, 0, 0], free: [214, 218, 222] },
};

// The grey is 255 - 2.55 × occupancy (0..100); alpha 0 is unknown. Read as
// ROS map_saver reads a grid: occupied from 0.65, free up to 0.196.
const gridShader = {
  vertex: `
    varying vec2 vUv;
    void main() {
      vUv = vec2(uv.x, 1.0 - uv.y);  // the image's first row is the plane's far (highest y) edge
      gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
    }`,
  fragment: `
    uniform sampler2D cells;
    uniform vec3 occupied;
    uniform vec3 free;
    varying vec2 vUv;
    void main() {
      vec4 t = texture2D(cells, vUv);
      if (t.a < 0.5) discard;
      float p = 1.0 - t.r;
      vec3 c = p >= 0.65 ? occupied : p <= 0.196 ? free : mix(free, occupied, p);
      gl_FragColor = vec4(c, 1.0);
    }`,
};

// GET /api/grid's answer as { session, v, patches, resolution, originX, originY, width, height, bitmap, bytes };
// null when the console holds no grid (204).
export async function fetchGrid() {
  const r = await fetch('/api/grid');
  if (r.status === 204) return null;
  if (!r.ok) throw new Error(`grid: ${r.status}`);
  const h = (name) => r.headers.get(name);
  const blob = await r.blob();
  // The pixels as they are in the file: no colour management, no premultiplied alpha.
  const bitmap = await createImageBitmap(blob, { premultiplyAlpha: 'none', colorSpaceConversion: 'none' });
  return { session: h('X-Grid-Session'), v: Number(h('X-Grid-Version')), patches: Number(h('X-Grid-Patches')),
           resolution: Number(h('X-Grid-Resolution')), originX: Number(h('X-Grid-Origin-X')),
           originY: Number(h('X-Grid-Origin-Y')), width: bitmap.width, height: bitmap.height, bitmap,
           bytes: blob.size };
}

// The grid's cells (nav_msgs values: -1 unknown, 0..100), row-major with row 0 at the lowest y as the payload's
// grid_patch_t, read back from the image the page holds.
function cellsOf(grid) {
  const { width, height } = grid;
  const canvas = document.createElement('canvas');
  canvas.width = width;
  canvas.height = height;
  const g = canvas.getContext('2d', { willReadFrequently: true });
  g.drawImage(grid.bitmap, 0, 0);
  const rgba = g.getImageData(0, 0, width, height).data;
  const cells = new Int8Array(width * height);
  for (let row = 0; row < height; ++row) {
    const from = (height - 1 - row) * width * 4;  // the image's top row is the grid's last
    for (let col = 0; col < width; ++col) {
      const p = from + col * 4;
      cells[row * width + col] = rgba[p + 3] < 128 ? -1 : Math.round((255 - rgba[p]) / 2.55);
    }
  }
  return cells;
}

export class GridLayer {
  constructor(parent) {
    this.parent = parent;  // the map view's group in the odometry frame
    this.grid = null;
    this.mesh = null;
    this.material = new THREE.ShaderMaterial({
      uniforms: { cells: { value: null }, occupied: { value: new THREE.Color() }, free: { value: new THREE.Color() } },
      vertexShader: gridShader.vertex,
      fragmentShader: gridShader.fragment,
      side: THREE.DoubleSide,
    });
    this.visible = true;
    this.onTop = false;
    this.setTheme(false);
  }

  version() { return this.grid ? this.grid.v : 0; }

  // What the page holds, for the tests: size, place, cell counts (occupied from 65) and an FNV-1a hash of the
  // cells in grid order (tests/console/harness.mjs servedGrid computes the same from the console's PNG).
  summary() {
    const g = this.grid;
    if (!g) return null;
    let occupied = 0, free = 0, unknown = 0, hash = 0x811c9dc5;
    for (const c of cellsOf(g)) {
      if (c < 0) unknown += 1; else if (c >= 65) occupied += 1; else free += 1;
      hash = Math.imul(hash ^ (c & 0xff), 0x01000193) >>> 0;
    }
    return { session: g.session, v: g.v, width: g.width, height: g.height, resolution: g.resolution,
             originX: g.originX, originY: g.originY, occupied, free, unknown, hash };
  }

  set(grid) {
    const z = this.mesh ? this.mesh.position.z : 0;
    this.drop();
    this.grid = grid;
    const texture = new THREE.Texture(grid.bitmap);
    texture.magFilter = THREE.NearestFilter;  // crisp cells up close
    texture.minFilter = THREE.LinearFilter;   // no mipmaps: any size works in WebGL 1
    texture.generateMipmaps = false;
    texture.flipY = false;                    // an ImageBitmap is not flipped on upload: the shader does it
    texture.needsUpdate = true;
    this.material.uniforms.cells.value = texture;
    const w = grid.width * grid.resolution, h = grid.height * grid.resolution;
    this.mesh = new THREE.Mesh(new THREE.PlaneBufferGeometry(w, h), this.material);
    this.mesh.position.set(grid.originX + w / 2, grid.originY + h / 2, z);
    this.mesh.renderOrder = this.onTop ? 1 : -1;
    this.mesh.visible = this.visible;
    this.parent.add(this.mesh);
  }

  clear() {
    this.drop();
    this.grid = null;
  }

  setTheme(sun) {
    const p = sun ? palettes.sun : palettes.dark;
    this.material.uniforms.occupied.value.setRGB(...p.occupied.map((c) => c / 255));
    this.material.uniforms.free.value.setRGB(...p.free.map((c) => c / 255));
    this.freeColour = p.free;
  }

  setVisible(on) {
    this.visible = on;
    if (this.mesh) this.mesh.visible = on;
  }

  // Over the points (drawn after them, whatever their depth) or under them.
  setOnTop(on) {
    this.onTop = on;
    this.material.depthTest = !on;
    if (this.mesh) this.mesh.renderOrder = on ? 1 : -1;
  }

  // The plane's height: just under the lowest point drawn.
  setFloor(z) {
    if (this.mesh) this.mesh.position.z = z - 0.05;
  }

  drop() {
    if (!this.mesh) return;
    this.parent.remove(this.mesh);
    this.mesh.geometry.dispose();
    this.material.uniforms.cells.value.dispose();
    this.material.uniforms.cells.value = null;
    this.grid.bitmap.close();
    this.mesh = null;
  }
}
