// The parts of three.js the linkage report's viewer uses, bundled into one classic script
// that sets `window.THREE` (ES module imports from file:// pages are blocked by CORS).
export {
  AmbientLight, ArrowHelper, BufferAttribute, BufferGeometry, Color, DirectionalLight,
  DoubleSide, Float32BufferAttribute, Group, LineBasicMaterial, LineSegments, Mesh,
  MeshLambertMaterial, OrthographicCamera, PerspectiveCamera, Scene, Vector3, WebGLRenderer
} from '../package/build/three.module.js';
export { OrbitControls } from '../package/examples/jsm/controls/OrbitControls.js';
