// The 3D viewer: a scan's mesh.glb (metres, +Y up, its texture or linear vertex colours) or,
// where no glb was written, its mesh.ply (millimetres, Z up, sRGB colours), with orbit controls.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { PLYLoader } from 'three/addons/loaders/PLYLoader.js';

export class Viewer {
  constructor(canvas) {
    this.canvas = canvas;
    // preserveDrawingBuffer: the picture can be read back (the browser test checks it)
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x20242a);
    this.camera = new THREE.PerspectiveCamera(35, 4 / 3, 0.001, 100);
    this.camera.position.set(0, 0.15, 0.5);
    this.scene.add(this.camera);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 1.6));
    const key = new THREE.DirectionalLight(0xffffff, 1.8);
    key.position.set(0.5, 1, 1);
    this.camera.add(key); // the light follows the eye: every side lit alike
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener('change', () => this.render());
    this.model = null;
    this.colour = true;
    new ResizeObserver(() => this.resize()).observe(canvas);
    this.resize();
  }

  resize() {
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    if (w === 0 || h === 0) return;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() { this.renderer.render(this.scene, this.camera); }

  clear() {
    if (this.model) {
      this.scene.remove(this.model);
      this.model.traverse((o) => { if (o.isMesh) { o.geometry.dispose(); o.material.dispose(); } });
      this.model = null;
    }
    delete this.canvas.dataset.loaded;
    document.getElementById('viewer-empty').hidden = false;
    this.render();
  }

  // Load @p base + 'mesh.glb' (or 'mesh.ply' when @p glb is false); resolves when drawn.
  async load(base, glb, id) {
    this.clear();
    let object;
    if (glb) {
      const gltf = await new GLTFLoader().loadAsync(base + 'mesh.glb');
      object = gltf.scene;
    } else {
      const geometry = await new PLYLoader().loadAsync(base + 'mesh.ply');
      const c = geometry.getAttribute('color');
      for (let i = 0; c && i < c.count; i++) { // the file's colours are sRGB; three works linear
        const col = new THREE.Color(c.getX(i), c.getY(i), c.getZ(i)).convertSRGBToLinear();
        c.setXYZ(i, col.r, col.g, col.b);
      }
      const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ vertexColors: !!c, roughness: 0.8 }));
      mesh.rotation.x = -Math.PI / 2; // the object frame's Z up -> three's Y up
      mesh.scale.setScalar(0.001);    // millimetres -> metres
      object = new THREE.Group();
      object.add(mesh);
    }
    this.model = object;
    this.scene.add(object);
    this.setColour(this.colour);
    this.frame();
    document.getElementById('viewer-empty').hidden = true;
    this.canvas.dataset.loaded = id;
  }

  // Look at the whole model from the front and a little above.
  frame() {
    const box = new THREE.Box3().setFromObject(this.model);
    const centre = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    this.controls.target.copy(centre);
    this.camera.position.copy(centre).add(new THREE.Vector3(0, size * 0.35, size * 1.4));
    this.camera.near = size / 100;
    this.camera.far = size * 20;
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.render();
  }

  setColour(on) {
    this.colour = on;
    if (!this.model) return;
    this.model.traverse((o) => {
      if (o.isMesh) {
        o.material.vertexColors = on && !!o.geometry.getAttribute('color');
        if (o.userData.map === undefined) o.userData.map = o.material.map; // the texture, kept
        o.material.map = on ? o.userData.map : null;
        o.material.needsUpdate = true;
      }
    });
    this.render();
  }
}
