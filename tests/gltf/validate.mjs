// The Khronos glTF validator on one .glb: prints its counts and every message, exits 1 on any
// error or warning. Usage: node tests/gltf/validate.mjs FILE.glb
import { readFile } from 'node:fs/promises';
import validator from 'gltf-validator';

const path = process.argv[2];
const bytes = new Uint8Array(await readFile(path));
const report = await validator.validateBytes(bytes, { maxIssues: 50 });
const { numErrors, numWarnings, numInfos, messages } = report.issues;
for (const m of messages)
    console.log(`${path}: ${['error', 'warning', 'info', 'hint'][m.severity]} ${m.code}: ` +
                `${m.message} (${m.pointer ?? ''})`);
const info = report.info ?? {};
console.log(`${path}: glTF ${info.version}, ${info.totalVertexCount} vertices, ` +
            `${info.totalTriangleCount} triangles, ${info.materialCount} material(s); ` +
            `${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos`);
process.exit(numErrors > 0 || numWarnings > 0 ? 1 : 0);
