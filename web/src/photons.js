// The photon map as a point cloud coloured by each photon's incoming direction (the
// paper's Fig. 3): red, green, blue follow the direction's x, y, z (0.5 + 0.5·d).
// /api/photons?format=points answers, for n photons, n × 3 float32 positions x, y, z (m),
// then n × 3 signed bytes of the direction of travel as it arrived (−127..127 for −1..1):
// 15 bytes a photon, drawn as they came.
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { q, request } from "./api.js";

export class PhotonView {
  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
    this.renderer.setClearColor(0x111418);
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.01, 1e4);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(2, -3, 2);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener("change", () => this.render());
    // resized in the next frame: resized at once, the canvas's new size is observed
    // again in the same turn, an error event ("ResizeObserver loop completed …")
    new ResizeObserver(() => requestAnimationFrame(() => this.resize())).observe(container);
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

  async load(path, channel, object, max) {
    let url = `/api/photons?format=points&path=${q(path)}&channel=${q(channel)}&max=${q(max)}`;
    if (object) url += `&object=${q(object)}`;
    const t0 = performance.now();
    const response = await request(url);
    const data = await response.arrayBuffer();
    this.total = Number(response.headers.get("X-Thzmap-Photons-Total")) || null;
    const t1 = performance.now();
    const n = Math.floor(data.byteLength / 15);
    if (this.points) {
      this.scene.remove(this.points);
      this.points.geometry.dispose();
    }
    // the arrays as they came: no copy, the colour computed on the GPU
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(new Float32Array(data, 0, 3 * n), 3));
    g.setAttribute("direction", new THREE.BufferAttribute(new Int8Array(data, 12 * n, 3 * n), 3, true));
    g.computeBoundingSphere();
    this.points = new THREE.Points(g, new THREE.ShaderMaterial({
      vertexShader: `attribute vec3 direction; varying vec3 colour;
        void main() { colour = 0.5 + 0.5 * direction;
          gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); gl_PointSize = 2.0; }`,
      fragmentShader: "varying vec3 colour; void main() { gl_FragColor = vec4(colour, 1.0); }",
    }));
    this.scene.add(this.points);
    if (n) {
      const { center, radius } = g.boundingSphere;
      this.controls.target.copy(center);
      this.camera.position.copy(center).add(new THREE.Vector3(0.8, -1.5, 0.9).multiplyScalar(radius * 1.6));
      this.controls.update();
    }
    this.resize();
    this.draw();
    this.timing = { fetch_ms: t1 - t0, draw_ms: performance.now() - t1 };
    return n;
  }

  render() {
    if (this.pending) return;
    this.pending = requestAnimationFrame(() => {
      this.pending = 0;
      this.draw();
    });
  }

  draw() {
    this.renderer.render(this.scene, this.camera);
  }
}
