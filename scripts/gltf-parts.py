#!/usr/bin/env python3
"""Checks that a .glb written by `sprig mesh` keeps the parts and colours its species says.

Usage: gltf-parts.py SPECIES.yaml FILE.glb [--expect NAME ...] [--textured NAME ...]

Reads the species file itself (PyYAML) and works out, independently of Sprig's code, which
parts the kind may export and each part's colour: trees wood/leaves/fruit from `render:`
(wood, leaf, fruit) or the documented defaults; shells whorl/varices/spines/bumps/inside from
`shell: textures:`; blobs and organisms from `render: color`; solids one part per material
(the species' own `materials:` colours, or the built-in table in solids/material.cpp, sRGB).
Then reads the GLB's JSON chunk and asserts: every node has a name the kind allows (or a
lower level of detail of one, PART_lodK) and a mesh
whose primitives use the material of the same name; each material's baseColorFactor equals
the expected colour (to 1e-6), alpha 1; leaves are double-sided and nothing else is; each
--expect NAME is present. A material with a baseColorTexture (a baked bark or shell texture)
must instead have baseColorFactor 1, the expected colour in extras.sprigBaseColor, an
embedded PNG (bufferView, image/png, PNG signature), TEXCOORD_0 and no COLOR_0; each
--textured NAME must be such a part. Prints one line per part; exits 1 on any mismatch.
"""
import json
import os
import re
import struct
import sys

import yaml


def srgb_to_linear(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def colour(value, default):
    if value is None:
        return default
    if isinstance(value, str):
        s = value.strip()
        return [srgb_to_linear(int(s[i:i + 2], 16) / 255.0) for i in (1, 3, 5)]
    return [float(v) for v in value]


def builtin_materials(root):
    text = open(os.path.join(root, 'solids', 'material.cpp')).read()
    out = {}
    for name, r, g, b in re.findall(r'make\("(\w+)", \{([\d.]+)f, ([\d.]+)f, ([\d.]+)f\}', text):
        out[name] = [srgb_to_linear(float(v)) for v in (r, g, b)]
    return out


def expected_parts(species, root):
    """{name: colour} the kind may export, and the names it must export."""
    kind = species.get('kind')
    render = species.get('render') or {}
    if kind == 'tree':
        return ({'wood': colour(render.get('wood'), [0.30, 0.20, 0.12]),
                 'leaves': colour(render.get('leaf'), [0.16, 0.38, 0.08]),
                 'fruit': colour(render.get('fruit'), [0.55, 0.08, 0.06])}, ['wood'])
    if kind == 'shell':
        t = (species.get('shell') or {}).get('textures') or {}
        return ({'whorl': colour(t.get('whorl'), [0.80, 0.72, 0.60]),
                 'varices': colour(t.get('varix'), [0.88, 0.84, 0.78]),
                 'spines': colour(t.get('axial'), [0.84, 0.80, 0.74]),
                 'bumps': colour(t.get('bump'), [0.70, 0.58, 0.46]),
                 'inside': colour(t.get('inside'), [0.93, 0.78, 0.74])}, [])
    if kind in ('blob', 'organism'):
        return ({kind: colour(render.get('color'), [0.72, 0.60, 0.48])}, [kind])
    if kind == 'solid':
        table = builtin_materials(root)
        for name, m in (species.get('materials') or {}).items():
            if isinstance(m, dict) and 'select' not in m:
                base = table.get(m.get('base'), [0.6, 0.6, 0.6])
                table[name] = colour(m.get('color'), base)
        return table, []
    raise SystemExit('gltf-parts: error: unknown kind %r' % kind)


def glb_json(path):
    data = open(path, 'rb').read()
    magic, version, length = struct.unpack_from('<4sII', data, 0)
    if magic != b'glTF' or version != 2 or length != len(data):
        raise SystemExit('gltf-parts: error: %s is not a glTF 2.0 binary' % path)
    chunk_length, chunk_type = struct.unpack_from('<II', data, 12)
    if chunk_type != 0x4E4F534A:
        raise SystemExit('gltf-parts: error: %s: the first chunk is not JSON' % path)
    return json.loads(data[20:20 + chunk_length])


def glb_bin(path):
    data = open(path, 'rb').read()
    json_length = struct.unpack_from('<I', data, 12)[0]
    offset = 20 + json_length
    bin_length, bin_type = struct.unpack_from('<II', data, offset)
    if bin_type != 0x004E4942:
        raise SystemExit('gltf-parts: error: %s: the second chunk is not BIN' % path)
    return data[offset + 8:offset + 8 + bin_length]


def main(argv):
    if len(argv) < 3:
        raise SystemExit(__doc__)
    species_path, glb_path = argv[1], argv[2]
    expect = [argv[i + 1] for i in range(3, len(argv) - 1) if argv[i] == '--expect']
    want_textured = [argv[i + 1] for i in range(3, len(argv) - 1) if argv[i] == '--textured']
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    species = yaml.safe_load(open(species_path))
    allowed, required = expected_parts(species, root)
    gltf = glb_json(glb_path)
    materials = gltf.get('materials', [])
    bad = []
    seen = []
    textured = []
    for node in gltf.get('nodes', []):
        # A part's lower levels of detail (MSFT_lod) are nodes named PART_lodK with the
        # part's material: checked as the part.
        seen.append(node.get('name'))
        name = re.sub(r'_lod[0-9]+$', '', node.get('name') or '')
        if name not in allowed:
            bad.append('node %r is not a part the species has (%s)' % (name, ', '.join(sorted(allowed))))
            continue
        mesh = gltf['meshes'][node['mesh']]
        for prim in mesh['primitives']:
            mat = materials[prim['material']]
            factor = mat['pbrMetallicRoughness'].get('baseColorFactor', [1, 1, 1, 1])
            want = allowed[name]
            if mat.get('name') != name:
                bad.append('node %r uses material %r' % (name, mat.get('name')))
            tex = mat['pbrMetallicRoughness'].get('baseColorTexture')
            if tex is not None:
                # A baked texture holds absolute colours: factor 1, the species' colour in extras.
                textured.append(name)
                if factor != [1, 1, 1, 1]:
                    bad.append('%s: textured, but baseColorFactor is %s, not 1' % (name, factor))
                factor = mat.get('extras', {}).get('sprigBaseColor', [-1, -1, -1]) + [1]
                image = gltf['images'][gltf['textures'][tex['index']]['source']]
                view = gltf['bufferViews'][image.get('bufferView', -1)] if 'bufferView' in image else None
                if image.get('mimeType') != 'image/png' or view is None:
                    bad.append('%s: the texture is not an embedded PNG' % name)
                elif glb_bin(glb_path)[view.get('byteOffset', 0):][:8] != b'\x89PNG\r\n\x1a\n':
                    bad.append('%s: the texture bytes are not a PNG' % name)
                if 'TEXCOORD_0' not in prim['attributes']:
                    bad.append('%s: textured without TEXCOORD_0' % name)
                if 'COLOR_0' in prim['attributes']:
                    bad.append('%s: textured and COLOR_0 (they multiply)' % name)
            if any(abs(a - b) > 1e-6 for a, b in zip(factor[:3], want)) or factor[3] != 1:
                bad.append('%s: baseColorFactor %s, the species says %s' % (name, factor, want))
            if bool(mat.get('doubleSided', False)) != (name == 'leaves'):
                bad.append('%s: doubleSided is %s' % (name, mat.get('doubleSided', False)))
            print('%s: %s part %s %s [%.4f, %.4f, %.4f]%s%s' % (
                glb_path, species.get('kind'), name, 'texture, sprigBaseColor' if tex is not None else 'baseColorFactor',
                factor[0], factor[1], factor[2],
                ' double-sided' if mat.get('doubleSided') else '',
                ' COLOR_0' if 'COLOR_0' in prim['attributes'] else ''))
    for name in required + expect + want_textured:
        if name not in seen:
            bad.append('no part named %r' % name)
    for name in want_textured:
        if name in seen and name not in textured:
            bad.append('part %r has no baseColorTexture' % name)
    if len(set(seen)) != len(seen):
        bad.append('repeated part names %s' % seen)
    for b in bad:
        print('%s: error: %s' % (glb_path, b))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
