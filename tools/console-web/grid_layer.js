// adit console: the live 2D occupancy grid under the point cloud. The console
// serves it in blocks of about 1024 cells a side (GET /api/grid/blocks lists
// them with their versions; GET /api/grid/block/X/Y is one as a PNG: grey +
// alpha, one pixel a cell, the top row the highest y; docs/CONSOLE.md), so a
// change costs the page its block only and no texture outgrows the GPU. The
// browser decodes each PNG off the main thread (createImageBitmap) and the GPU
// takes it as it is: a horizontal plane in the map frame just under the lowest
// point, coloured in the shader (occupied dark, free light, unknown not drawn),
// so a new block costs the page no per-cell work. Seen from above (the top
// view) a mine's roof would hide the grid: there it is drawn over the points.
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

// GET /api/grid/blocks' answer: { session, v, patches, resolution, block_cells, origin_x, origin_y, width,
// height, blocks: [[x, y, v], ...] }; null when the console holds no grid (204).
export async function fetchGridBlocks() {
  const r = await fetch('/api/grid/blocks');
  if (r.status === 204) return null;
  if (!r.ok) throw new Error(`grid blocks: ${r.status}`);
  return r.json();
}

// GET /api/grid/block/X/Y's answer as { x, y, session, v, resolution, originX, originY, width, height, bitmap,
// bytes }; null when the console holds no such block (204: a new session emptied it).
export async function fetchGridBlock(x, y) {
  const r = await fetch(`/api/grid/block/${x}/${y}`);
  if (r.status === 204) return null;
  if (!r.ok) throw new Error(`grid block (${x}, ${y}): ${r.status}`);
  const h = (name) => r.headers.get(name);
  const blob = await r.blob();
  // The pixels as they are in the file: no colour management, no premultiplied alpha.
  const bitmap = await createImageBitmap(blob, { premultiplyAlpha: 'none', colorSpaceConversion: 'none' });
  return { x, y, session: h('X-Grid-Session'), v: Number(h('X-Grid-Version')), resolution: Number(h('X-Grid-Resolution')),
           originX: Number(h('X-Grid-Origin-X')), originY: Number(h('X-Grid-Origin-Y')), width: bitmap.width,
           height: bitmap.height, bitmap, bytes: blob.size };
}

// The grid's cells over the list's extent (nav_msgs values: -1 unknown, 0..100), row-major with row 0 at the
// lowest y as the payload's grid_patch_t, read back from the blocks the page holds.
function cellsOf(index, blocks) {
  const { width, height, resolution } = index;
  const canvas = document.createElement('canvas');
  canvas.width = width;
  canvas.height = height;
  const g = canvas.getContext('2d', { willReadFrequently: true });
  const top = index.origin_y + height * resolution;  // the image's first row is the highest y
  for (const b of blocks) {
    g.drawImage(b.bitmap, Math.round((b.originX - index.origin_x) / resolution),
                Math.round((top - (b.originY + b.height * resolution)) / resolution));
  }
  const rgba = g.getImageData(0, 0, width, height).data;
  const cells = new Int8Array(width * height);
  for (let row = 0; row < height; ++row) {
    const from = (height - 1 - row) * width * 4;
    for (let col = 0; col < width; ++col) {
      const p = from + col * 4;
      cells[row * width + col] = rgba[p + 3] < 128 ? -1 : Math.round((255 - rgba[p]) / 2.55);
    }
  }
  return cells;
}

export class GridLayer {
  constructor(parent) {
    this.group = new THREE.Group();  // in the map view's tiles frame; its height follows the lowest point
    parent.add(this.group);
    this.index = null;        // the block list last applied
    this.blocks = new Map();  // 'x,y' -> { ...fetchGridBlock's answer, mesh }
    // Shared by every block's material: a theme change recolours them all.
    this.colours = { occupied: { value: new THREE.Color() }, free: { value: new THREE.Color() } };
    this.visible = true;
    this.onTop = false;
    this.setTheme(false);
  }

  version() { return this.index ? this.index.v : 0; }
  blockVersion(x, y) {
    const b = this.blocks.get(`${x},${y}`);
    return b ? b.v : 0;
  }

  // What the page holds, for the tests: size, place, cell counts (occupied from 65) and an FNV-1a hash of the
  // cells in grid order (tests/console/harness.mjs servedGrid computes the same from the console's whole PNG).
  summary() {
    const g = this.index;
    if (!g) return null;
    let occupied = 0, free = 0, unknown = 0, hash = 0x811c9dc5;
    for (const c of cellsOf(g, this.blocks.values())) {
      if (c < 0) unknown += 1; else if (c >= 65) occupied += 1; else free += 1;
      hash = Math.imul(hash ^ (c & 0xff), 0x01000193) >>> 0;
    }
    return { session: g.session, v: g.v, width: g.width, height: g.height, resolution: g.resolution,
             originX: g.origin_x, originY: g.origin_y, occupied, free, unknown, hash };
  }

  // A block fetched (fetchGridBlock), in place of the one held there: the same
  // plane takes the new texture when the block kept its place and size.
  setBlock(block) {
    const key = `${block.x},${block.y}`;
    const texture = new THREE.Texture(block.bitmap);
    texture.magFilter = THREE.NearestFilter;  // crisp cells up close
    texture.minFilter = THREE.LinearFilter;   // no mipmaps: any size works in WebGL 1
    texture.generateMipmaps = false;
    texture.flipY = false;                    // an ImageBitmap is not flipped on upload: the shader does it
    texture.needsUpdate = true;
    const held = this.blocks.get(key);
    if (held && held.width === block.width && held.height === block.height && held.originX === block.originX &&
        held.originY === block.originY) {
      const cells = held.mesh.material.uniforms.cells;
      cells.value.dispose();
      held.bitmap.close();
      cells.value = texture;
      this.blocks.set(key, { ...block, mesh: held.mesh });
      return;
    }
    this.dropBlock(key);
    const material = new THREE.ShaderMaterial({
      uniforms: { cells: { value: texture }, occupied: this.colours.occupied, free: this.colours.free },
      vertexShader: gridShader.vertex,
      fragmentShader: gridShader.fragment,
      side: THREE.DoubleSide,
      depthTest: !this.onTop,
    });
    const w = block.width * block.resolution, h = block.height * block.resolution;
    const mesh = new THREE.Mesh(new THREE.PlaneBufferGeometry(w, h), material);
    mesh.position.set(block.originX + w / 2, block.originY + h / 2, 0);
    mesh.renderOrder = this.onTop ? 1 : -1;
    this.group.add(mesh);
    this.blocks.set(key, { ...block, mesh });
  }

  // The block list the blocks held now answer (fetchGridBlocks); blocks it does not name are dropped.
  setIndex(index) {
    const named = new Set(index.blocks.map(([x, y]) => `${x},${y}`));
    for (const key of [...this.blocks.keys()]) if (!named.has(key)) this.dropBlock(key);
    this.index = index;
  }

  clear() {
    for (const key of [...this.blocks.keys()]) this.dropBlock(key);
    this.index = null;
  }

  setTheme(sun) {
    const p = sun ? palettes.sun : palettes.dark;
    this.colours.occupied.value.setRGB(...p.occupied.map((c) => c / 255));
    this.colours.free.value.setRGB(...p.free.map((c) => c / 255));
    this.freeColour = p.free;
  }

  setVisible(on) {
    this.visible = on;
    this.group.visible = on;
  }

  // Over the points (drawn after them, whatever their depth) or under them.
  setOnTop(on) {
    if (on === this.onTop) return;
    this.onTop = on;
    for (const b of this.blocks.values()) {
      b.mesh.material.depthTest = !on;
      b.mesh.renderOrder = on ? 1 : -1;
    }
  }

  // The planes' height: just under the lowest point drawn.
  setFloor(z) {
    this.group.position.z = z - 0.05;
  }

  dropBlock(key) {
    const b = this.blocks.get(key);
    if (!b) return;
    this.group.remove(b.mesh);
    b.mesh.geometry.dispose();
    b.mesh.material.uniforms.cells.value.dispose();
    b.mesh.material.dispose();
    b.bitmap.close();
    this.blocks.delete(key);
  }
}
