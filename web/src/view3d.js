// The scene in 3D (three.js): objects from /api/validate's meshes, coloured by material or
// temperature, face normals on demand, the enclosure cut away by back-face culling,
// sensors as frusta, and a live pinhole preview from the selected sensor in a corner.
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { viridis } from "./colour.js";

const flat = (a) => (a && Array.isArray(a[0]) ? a.flat() : a || []);

// sensor: one of /api/validate's scene.sensors, as the library resolved it (position,
// unit direction and up, horizontal angle of view, rows and columns): no defaults here.
export function sensorCamera(sensor) {
  const { columns: cols, rows } = sensor;
  const hfov = (sensor.fov_deg * Math.PI) / 180;
  const vfov = 2 * Math.atan(Math.tan(hfov / 2) * (rows / cols));
  const cam = new THREE.PerspectiveCamera((vfov * 180) / Math.PI, cols / rows, 0.01, 1e4);
  const pos = new THREE.Vector3(...sensor.position_m);
  cam.position.copy(pos);
  cam.up.set(...sensor.up);
  cam.lookAt(pos.clone().add(new THREE.Vector3(...sensor.direction)));
  cam.updateMatrixWorld();
  return cam;
}

export class SceneView {
  constructor(container, onPick) {
    this.container = container;
    this.onPick = onPick;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    this.renderer.setClearColor(0xe8ebef);
    this.renderer.autoClear = false;
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.2);
    sun.position.set(2, -3, 5);
    this.scene.add(sun);
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.01, 1e4);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(2.5, -4, 3);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener("change", () => this.render());
    this.group = new THREE.Group();
    this.scene.add(this.group);
    this.meshes = [];
    this.options = { colourBy: "material", normals: false, cut: true, preview: true };
    this.selectedSensor = 0;
    // resized in the next frame: resized at once, the canvas's new size is observed
    // again in the same turn, an error event ("ResizeObserver loop completed …")
    new ResizeObserver(() => requestAnimationFrame(() => this.resize())).observe(container);
    this.renderer.domElement.addEventListener("pointerdown", (e) => (this.down = [e.clientX, e.clientY]));
    this.renderer.domElement.addEventListener("pointerup", (e) => this.pick(e));
    this.framed = false;
  }

  resize() {
    const w = this.container.clientWidth;
    const h = this.container.clientHeight;
    if (!w || !h) return;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  // info: /api/validate's "scene"; doc: the scene's JSON as edited
  update(info, doc) {
    this.info = info;
    this.doc = doc;
    for (const child of [...this.group.children]) {
      this.group.remove(child);
      child.geometry?.dispose();
      child.material?.dispose();
    }
    this.meshes = [];
    const objects = info?.objects || [];
    const temps = objects.map((o) => o.temperature_K ?? o.temperature_k).filter(Number.isFinite);
    this.tRange = [Math.min(...temps), Math.max(...temps)];
    const box = new THREE.Box3();
    objects.forEach((o, index) => {
      if (!o.mesh) return;
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute("position", new THREE.Float32BufferAttribute(flat(o.mesh.positions), 3));
      geometry.setIndex(flat(o.mesh.indices));
      const shaded = geometry.toNonIndexed(); // flat shading: each face its own normal
      shaded.computeVertexNormals();
      geometry.dispose();
      const material = new THREE.MeshLambertMaterial({
        color: this.colourOf(o, doc),
        side: this.options.cut && o.type !== "shell" ? THREE.FrontSide : THREE.DoubleSide,
        transparent: o.type === "shell",
        opacity: o.type === "shell" ? 0.75 : 1,
      });
      const mesh = new THREE.Mesh(shaded, material);
      mesh.userData = { index, object: o };
      this.group.add(mesh);
      this.meshes.push(mesh);
      shaded.computeBoundingBox();
      box.union(shaded.boundingBox);
      if (this.options.normals) {
        const lines = normalLines(shaded, index === this.selectedObject);
        lines.userData.helper = true;
        this.group.add(lines);
      }
    });
    (info?.sensors || []).forEach((s, i) => this.group.add(frustum(s, i === this.selectedSensor)));
    this.legend();
    if (!this.framed && !box.isEmpty()) {
      const centre = box.getCenter(new THREE.Vector3());
      const size = box.getSize(new THREE.Vector3()).length();
      this.controls.target.copy(centre);
      this.camera.position.copy(centre).add(new THREE.Vector3(0.9, -1.4, 0.9).multiplyScalar(size));
      this.camera.near = size / 1000;
      this.camera.far = size * 100;
      this.camera.updateProjectionMatrix();
      this.controls.update();
      this.framed = true;
    }
    this.render();
  }

  // the temperature colours' key beside the toolbar's "Colour by"
  legend() {
    const el = document.getElementById("legend3d");
    if (this.options.colourBy !== "temperature" || !Number.isFinite(this.tRange[0])) {
      el.textContent = "";
      return;
    }
    const stops = [0, 0.25, 0.5, 0.75, 1].map((t) => `rgb(${viridis(t).map(Math.round).join(",")})`);
    el.innerHTML = "";
    const ramp = document.createElement("span");
    ramp.className = "legend-ramp";
    ramp.style.background = `linear-gradient(to right, ${stops.join(", ")})`;
    el.append(`${this.tRange[0]} K `, ramp, ` ${this.tRange[1]} K`);
  }

  colourOf(o, doc) {
    if (this.options.colourBy === "temperature") {
      const t = o.temperature_K ?? o.temperature_k;
      const [lo, hi] = this.tRange;
      const rgb = viridis(hi > lo ? (t - lo) / (hi - lo) : 0.5);
      return new THREE.Color(rgb[0] / 255, rgb[1] / 255, rgb[2] / 255);
    }
    return new THREE.Color(...materialColour(doc, o.material));
  }

  highlight(index) {
    this.selectedObject = index;
    for (const m of this.meshes) {
      m.material.emissive = new THREE.Color(m.userData.index === index ? 0x333300 : 0x000000);
    }
    if (this.options.normals) this.update(this.info, this.doc);
    else this.render();
  }

  pick(e) {
    if (!this.down || Math.hypot(e.clientX - this.down[0], e.clientY - this.down[1]) > 4) return;
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1,
      -((e.clientY - rect.top) / rect.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    const hit = ray.intersectObjects(this.meshes, false).find((h) =>
      h.object.material.side === THREE.DoubleSide || h.face.normal.dot(ray.ray.direction) < 0);
    if (hit) this.onPick(hit.object.userData.index);
  }

  // one frame per animation frame, however many changes asked for it
  render() {
    if (this.pending) return;
    this.pending = requestAnimationFrame(() => {
      this.pending = 0;
      this.draw();
    });
  }

  draw() {
    const r = this.renderer;
    const w = this.container.clientWidth;
    const h = this.container.clientHeight;
    r.setViewport(0, 0, w, h);
    r.setScissorTest(false);
    r.clear();
    r.render(this.scene, this.camera);
    const sensor = this.info?.sensors?.[this.selectedSensor];
    if (!this.options.preview || !sensor) return;
    // the pinhole preview: what the sensor sees, its aspect, in the lower right corner
    const cam = sensorCamera(sensor);
    const pw = Math.round(Math.min(w * 0.3, 260));
    const ph = Math.round(pw / cam.aspect);
    const frusta = this.group.children.filter((c) => c.userData.helper); // frusta, normals
    frusta.forEach((f) => (f.visible = false));
    r.setScissorTest(true);
    r.setScissor(w - pw - 8, 8, pw, ph);
    r.setViewport(w - pw - 8, 8, pw, ph);
    r.setClearColor(0x000000);
    r.clear();
    r.render(this.scene, cam);
    r.setClearColor(0xe8ebef);
    r.setScissorTest(false);
    frusta.forEach((f) => (f.visible = true));
  }
}

export function materialColour(doc, name) {
  const c = doc?.materials?.[name]?.color;
  if (Array.isArray(c) && c.length === 3) return c;
  let h = 0;
  for (const ch of String(name)) h = (h * 31 + ch.charCodeAt(0)) >>> 0;
  return new THREE.Color().setHSL((h % 360) / 360, 0.55, 0.55).toArray();
}

function normalLines(geometry, selected) {
  const pos = geometry.getAttribute("position");
  const tri = pos.count / 3;
  const step = Math.max(1, Math.floor(tri / 20000)); // at most 20 000 arrows
  geometry.computeBoundingSphere();
  const len = geometry.boundingSphere.radius * 0.08;
  const pts = [];
  const a = new THREE.Vector3();
  const b = new THREE.Vector3();
  const c = new THREE.Vector3();
  for (let t = 0; t < tri; t += step) {
    a.fromBufferAttribute(pos, 3 * t);
    b.fromBufferAttribute(pos, 3 * t + 1);
    c.fromBufferAttribute(pos, 3 * t + 2);
    const centre = a.clone().add(b).add(c).divideScalar(3);
    const n = b.clone().sub(a).cross(c.clone().sub(a)).normalize().multiplyScalar(len);
    pts.push(centre, centre.clone().add(n));
  }
  const g = new THREE.BufferGeometry().setFromPoints(pts);
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: selected ? 0xff0000 : 0xcc3366 }));
}

function frustum(sensor, selected) {
  const cam = sensorCamera(sensor);
  cam.far = 0.4;
  cam.updateProjectionMatrix();
  const corners = [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([x, y]) =>
    new THREE.Vector3(x, y, 1).unproject(cam));
  const o = cam.position;
  const pts = [];
  corners.forEach((c, i) => pts.push(o, c, c, corners[(i + 1) % 4]));
  const up = new THREE.Vector3(0, 1.25, 1).unproject(cam); // a tick on the image's top side
  pts.push(corners[2], up, up, corners[3]);
  const lines = new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(pts),
    new THREE.LineBasicMaterial({ color: selected ? 0xe06000 : 0x333333 }));
  lines.userData.helper = true;
  return lines;
}
