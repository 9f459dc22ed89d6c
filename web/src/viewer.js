// The 3-D view: a binary glTF from POST /v1/tessellate (format "glb"), one node per face
// or curve named by its id in the file; shaded faces, curves as lines, picking by ray.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const FACE_COLOR = 0xb8c4d0;
const LINE_COLOR = 0x1b2a3a;
const PICK_COLOR = 0xe07a10;

export class Viewer {
  /** @param {HTMLElement} host  @param {(id: string|null) => void} onPick */
  constructor(host, onPick) {
    this.host = host;
    this.onPick = onPick;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    this.renderer.setClearColor(0xf4f6f8);
    this.renderer.domElement.setAttribute('aria-hidden', 'true');
    host.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
    this.camera.position.set(1, -1.4, 1);
    this.camera.up.set(0, 0, 1);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x707880, 1.6));
    this.light = new THREE.DirectionalLight(0xffffff, 1.6);
    this.camera.add(this.light);
    this.light.position.set(0.5, 1, 0.2);
    this.scene.add(this.camera);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    // Keyboard: arrows pan, Shift (Ctrl, Meta) + arrows orbit (OrbitControls), + and - zoom,
    // when the view has the focus.
    host.tabIndex = 0;
    this.controls.listenToKeyEvents(host);
    host.addEventListener('keydown', (e) => {
      if (e.key === '+' || e.key === '=' || e.key === '-') {
        const f = e.key === '-' ? 1.25 : 0.8;
        this.camera.position.sub(this.controls.target).multiplyScalar(f).add(this.controls.target);
        this.controls.update();
        e.preventDefault();
      }
    });
    this.root = null;
    /** id -> [Object3D] */
    this.byId = new Map();
    /** The ids highlighted now. */
    this.picked = [];
    this.showLines = true;
    this.ray = new THREE.Raycaster();
    this.#pointerPicking();
    new ResizeObserver(() => this.resize()).observe(host);
    this.resize();
  }

  resize() {
    const w = Math.max(1, this.host.clientWidth);
    const h = Math.max(1, this.host.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
  }

  clear() {
    if (this.root) {
      this.scene.remove(this.root);
      this.root.traverse((o) => {
        o.geometry?.dispose();
        o.material?.dispose();
      });
    }
    this.root = null;
    this.byId.clear();
    this.picked = [];
    this.render();
  }

  /** Shows a binary glTF; resolves with {faces, curves}: the node names of each kind. */
  async load(glb) {
    this.clear();
    const gltf = await new GLTFLoader().parseAsync(glb, '');
    const names = gltf.parser.json.nodes ?? [];
    const faces = [];
    const curves = [];
    const root = gltf.scene;
    root.traverse((o) => {
      if (!(o.isMesh || o.isLine)) return;
      // The node's name as the file wrote it (the loader sanitises object names).
      let id = o.name;
      const assoc = gltf.parser.associations.get(o);
      if (assoc && assoc.nodes != null && names[assoc.nodes]?.name) id = names[assoc.nodes].name;
      o.userData.id = id;
      if (o.isMesh) {
        o.geometry.computeVertexNormals();
        o.material = new THREE.MeshStandardMaterial({
          color: FACE_COLOR, side: THREE.DoubleSide, metalness: 0.05, roughness: 0.6,
          polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
        });
        faces.push(id);
      } else {
        o.material = new THREE.LineBasicMaterial({ color: LINE_COLOR });
        curves.push(id);
      }
      if (!this.byId.has(id)) this.byId.set(id, []);
      this.byId.get(id).push(o);
    });
    this.root = root;
    this.scene.add(root);
    this.setLinesVisible(this.showLines);
    this.fit();
    return { faces, curves };
  }

  setLinesVisible(on) {
    this.showLines = on;
    this.root?.traverse((o) => {
      if (o.isLine) o.visible = on;
    });
    this.render();
  }

  /** Frames the whole part. */
  fit() {
    if (!this.root) return;
    const box = new THREE.Box3().setFromObject(this.root);
    if (box.isEmpty()) return;
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    const r = Math.max(sphere.radius, 1e-9);
    const dist = r / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 1.05;
    const dir = new THREE.Vector3(1, -1.4, 1).normalize();
    this.camera.near = dist / 1000;
    this.camera.far = dist * 10;
    this.camera.position.copy(sphere.center).addScaledVector(dir, dist);
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(sphere.center);
    this.controls.update();
    this.ray.params.Line.threshold = r * 0.01;
    this.render();
  }

  /** The part's size (bounding-box diagonal), 0 when empty. */
  size() {
    if (!this.root) return 0;
    const box = new THREE.Box3().setFromObject(this.root);
    return box.isEmpty() ? 0 : box.getSize(new THREE.Vector3()).length();
  }

  has(id) {
    return this.byId.has(id);
  }

  /** Highlights the objects named `ids` (others back to normal). */
  highlight(ids) {
    const want = new Set(ids);
    this.picked = [...this.byId.keys()].filter((id) => want.has(id));
    for (const [id, objs] of this.byId) {
      for (const o of objs) {
        const base = o.isMesh ? FACE_COLOR : LINE_COLOR;
        o.material.color.setHex(want.has(id) ? PICK_COLOR : base);
      }
    }
    this.render();
  }

  /** The length of a drawn curve (sum of its polyline's segments), or null. */
  polylineLength(id) {
    const objs = this.byId.get(id)?.filter((o) => o.isLine);
    if (!objs?.length) return null;
    let sum = 0;
    for (const o of objs) {
      const p = o.geometry.getAttribute('position');
      for (let i = 1; i < p.count; i += 1) {
        sum += Math.hypot(p.getX(i) - p.getX(i - 1), p.getY(i) - p.getY(i - 1), p.getZ(i) - p.getZ(i - 1));
      }
    }
    return sum;
  }

  /** The id under a canvas point (client coordinates), or null. */
  pick(clientX, clientY) {
    if (!this.root) return null;
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(
      ((clientX - rect.left) / rect.width) * 2 - 1,
      -((clientY - rect.top) / rect.height) * 2 + 1,
    );
    this.ray.setFromCamera(ndc, this.camera);
    const targets = [];
    this.root.traverse((o) => {
      if ((o.isMesh || o.isLine) && o.visible) targets.push(o);
    });
    const hits = this.ray.intersectObjects(targets, false);
    // A curve within the pick threshold in front of the nearest face wins: edges lie on faces.
    const face = hits.find((h) => h.object.isMesh);
    const line = hits.find((h) => h.object.isLine && (!face || h.distance <= face.distance * 1.001));
    return (line ?? face)?.object.userData.id ?? null;
  }

  /**
   * Client coordinates of a point of a face's mesh (the first triangle's centroid) or of a
   * curve (its polyline's vertex at the fraction `t` of its vertices).
   */
  screenPointOf(id, t = 0.5) {
    const objs = this.byId.get(id) ?? [];
    const obj = objs.find((o) => o.isMesh) ?? objs.find((o) => o.isLine);
    if (!obj) return null;
    const p = obj.geometry.getAttribute('position');
    let c;
    if (obj.isMesh) {
      const idx = obj.geometry.index;
      const corner = (k) => new THREE.Vector3().fromBufferAttribute(p, idx ? idx.getX(k) : k);
      c = corner(0).add(corner(1)).add(corner(2)).multiplyScalar(1 / 3);
    } else {
      c = new THREE.Vector3().fromBufferAttribute(p, Math.round(Math.min(1, Math.max(0, t)) * (p.count - 1)));
    }
    obj.localToWorld(c);
    c.project(this.camera);
    const rect = this.renderer.domElement.getBoundingClientRect();
    return { x: rect.left + ((c.x + 1) / 2) * rect.width, y: rect.top + ((1 - c.y) / 2) * rect.height };
  }

  #pointerPicking() {
    const el = this.renderer.domElement;
    let down = null;
    el.addEventListener('pointerdown', (e) => {
      down = { x: e.clientX, y: e.clientY };
    });
    el.addEventListener('pointerup', (e) => {
      if (!down || e.button !== 0) return;
      const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
      down = null;
      if (moved < 4) this.onPick(this.pick(e.clientX, e.clientY));
    });
  }
}
