// The 3-D viewer of subfit's report.html (crates/subfit-report/src/html.rs writes the page).
//
// The page carries its scene as JSON in <script id="subfit-scene" type="application/json">:
//   { "up": [0, 0, 1] | null,
//     "layers": [ { "name", "kind": "mesh" | "lines" | "points", "visible": bool,
//                   "positions": base64 f32 xyz, "indices": base64 u32 (triangles or segments),
//                   "colors": base64 u8 rgb | null, "values": base64 f32 | null,
//                   "value_label": "…", "color": "#rrggbb" } ] }
// and the viewer draws it into <div id="subfit-viewer"> with orbit controls, a check box per
// layer, one for the error colours of the meshes, and a read-out of the value under a click.
// Everything is inlined into the page: nothing is fetched at view time.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

function decode(b64, Type) {
  if (!b64) return null;
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Type(bytes.buffer);
}

function webglAvailable() {
  try {
    const c = document.createElement('canvas');
    return !!(window.WebGLRenderingContext && (c.getContext('webgl2') || c.getContext('webgl')));
  } catch (e) {
    return false;
  }
}

function message(container, text) {
  const p = document.createElement('p');
  p.className = 'viewer-message';
  p.textContent = text;
  container.appendChild(p);
}

function buildLayer(layer, state) {
  const positions = decode(layer.positions, Float32Array);
  const indices = decode(layer.indices, Uint32Array);
  const colors = decode(layer.colors, Uint8Array);
  const values = decode(layer.values, Float32Array);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  if (indices && indices.length) geometry.setIndex(new THREE.BufferAttribute(indices, 1));
  if (colors) geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3, true));
  geometry.computeBoundingSphere();
  const base = new THREE.Color(layer.color || '#b0b0b0');
  let object;
  if (layer.kind === 'mesh') {
    geometry.computeVertexNormals();
    const material = new THREE.MeshLambertMaterial({
      color: colors ? 0xffffff : base,
      vertexColors: !!colors,
      side: THREE.DoubleSide,
      polygonOffset: true,
      polygonOffsetFactor: 1,
      polygonOffsetUnits: 1,
    });
    object = new THREE.Mesh(geometry, material);
    object.userData.toggleColors = (on) => {
      material.vertexColors = on && !!colors;
      material.color = on && colors ? new THREE.Color(0xffffff) : base;
      material.needsUpdate = true;
    };
  } else if (layer.kind === 'lines') {
    object = new THREE.LineSegments(
      geometry,
      new THREE.LineBasicMaterial({ color: base, transparent: true, opacity: 0.85 }),
    );
  } else {
    const size = state.radius / 400;
    object = new THREE.Points(
      geometry,
      new THREE.PointsMaterial({
        color: colors ? 0xffffff : base,
        vertexColors: !!colors,
        size,
        sizeAttenuation: true,
      }),
    );
  }
  object.visible = layer.visible !== false;
  object.name = layer.name;
  object.userData.values = values;
  object.userData.valueLabel = layer.value_label || '';
  return object;
}

function start() {
  const container = document.getElementById('subfit-viewer');
  const sceneNode = document.getElementById('subfit-scene');
  if (!container || !sceneNode) return;
  const spec = JSON.parse(sceneNode.textContent);
  if (!spec.layers || !spec.layers.length) {
    message(container, 'No geometry in this report.');
    return;
  }
  if (!webglAvailable()) {
    message(container, 'This browser has no WebGL: the 3-D view is unavailable (the plots and tables below are not affected).');
    return;
  }

  // Bounding sphere of every layer, from the raw positions (before building objects).
  const box = new THREE.Box3();
  for (const layer of spec.layers) {
    const p = decode(layer.positions, Float32Array);
    for (let i = 0; i + 2 < p.length; i += 3) box.expandByPoint(new THREE.Vector3(p[i], p[i + 1], p[i + 2]));
  }
  const center = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-9);

  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const width = () => container.clientWidth || 800;
  const height = () => container.clientHeight || 600;
  renderer.setSize(width(), height());
  renderer.setClearColor(0xf4f4f4, 1);
  container.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(35, width() / height(), radius / 100, radius * 100);
  if (spec.up) camera.up.set(spec.up[0], spec.up[1], spec.up[2]);
  scene.add(new THREE.AmbientLight(0xffffff, 1.2));
  const headlight = new THREE.DirectionalLight(0xffffff, 1.8);
  camera.add(headlight);
  headlight.position.set(0.3, 0.5, 1);
  scene.add(camera);

  const state = { radius };
  const objects = spec.layers.map((layer) => {
    const object = buildLayer(layer, state);
    scene.add(object);
    return object;
  });

  const controls = new OrbitControls(camera, renderer.domElement);
  const home = () => {
    const view = new THREE.Vector3(0.55, 0.35, 1).normalize();
    if (spec.up && spec.up[2] === 1) view.set(0.6, -1, 0.45).normalize();
    const distance = (radius / Math.sin((camera.fov * Math.PI) / 360)) * 0.8;
    camera.position.copy(center).addScaledVector(view, distance);
    controls.target.copy(center);
    camera.lookAt(center);
    controls.update();
  };
  home();

  let pending = false;
  const draw = () => {
    pending = false;
    renderer.render(scene, camera);
  };
  const redraw = () => {
    if (!pending) {
      pending = true;
      requestAnimationFrame(draw);
    }
  };
  controls.addEventListener('change', redraw);
  // A lost WebGL context (a GPU process restarted; three.js asks for it back) comes back
  // empty: draw again once it is restored.
  renderer.domElement.addEventListener('webglcontextrestored', redraw);
  window.addEventListener('resize', () => {
    camera.aspect = width() / height();
    camera.updateProjectionMatrix();
    renderer.setSize(width(), height());
    redraw();
  });

  // Toggles: one per layer, one for the error colours, and the home view.
  const bar = document.getElementById('subfit-viewer-controls');
  if (bar) {
    objects.forEach((object) => {
      const label = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = object.visible;
      box.dataset.layer = object.name;
      box.addEventListener('change', () => {
        object.visible = box.checked;
        redraw();
      });
      label.append(box, ' ' + object.name);
      bar.appendChild(label);
    });
    if (objects.some((o) => o.userData.toggleColors)) {
      const label = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = true;
      box.id = 'subfit-error-colors';
      box.addEventListener('change', () => {
        objects.forEach((o) => o.userData.toggleColors && o.userData.toggleColors(box.checked));
        redraw();
      });
      label.append(box, ' error colours');
      bar.appendChild(label);
    }
    const reset = document.createElement('button');
    reset.type = 'button';
    reset.textContent = 'reset view';
    reset.addEventListener('click', () => {
      home();
      redraw();
    });
    bar.appendChild(reset);
  }

  // Click read-out: the value at the nearest vertex of the picked triangle.
  const readout = document.getElementById('subfit-viewer-readout');
  const raycaster = new THREE.Raycaster();
  let down = null;
  renderer.domElement.addEventListener('pointerdown', (e) => {
    down = [e.clientX, e.clientY];
  });
  renderer.domElement.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4 || !readout) return;
    const rect = renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(
      ((e.clientX - rect.left) / rect.width) * 2 - 1,
      -((e.clientY - rect.top) / rect.height) * 2 + 1,
    );
    raycaster.setFromCamera(ndc, camera);
    const meshes = objects.filter((o) => o.visible && o.isMesh && o.userData.values);
    const hit = raycaster.intersectObjects(meshes, false)[0];
    if (!hit || !hit.face) {
      readout.textContent = '';
      return;
    }
    const values = hit.object.userData.values;
    const position = hit.object.geometry.getAttribute('position');
    let best = hit.face.a;
    let bestDistance = Infinity;
    for (const v of [hit.face.a, hit.face.b, hit.face.c]) {
      const d = new THREE.Vector3().fromBufferAttribute(position, v).distanceTo(hit.point);
      if (d < bestDistance) {
        bestDistance = d;
        best = v;
      }
    }
    readout.textContent = `${hit.object.name}: ${hit.object.userData.valueLabel} ${values[best].toExponential(3)} at (${hit.point.x.toPrecision(4)}, ${hit.point.y.toPrecision(4)}, ${hit.point.z.toPrecision(4)})`;
  });

  draw();
  container.dataset.ready = 'true';
}

if (document.readyState === 'loading') {
  document.addEventListener('DOMContentLoaded', start);
} else {
  start();
}
