// obj_tinyobj.cpp: the one C++ file: tinyobjloader behind a C interface.
// No exception crosses into C; every allocation handed to C is malloc'd.
#include <tiny_obj_loader.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>

extern "C" {
#include "scene/obj.h"
}

namespace {

void set_msg(char *msg, size_t n, const std::string &s)
{
    // tinyobjloader's messages end in newlines and may hold several lines:
    // keep the first, as the caller prints exactly one.
    std::string first = s.substr(0, s.find('\n'));
    std::snprintf(msg, n, "%s", first.c_str());
}

template <typename T> T *alloc_array(size_t count)
{
    if (count == 0)
        count = 1; // a valid pointer even for empty arrays keeps the C side simple
    if (count > SIZE_MAX / sizeof(T))
        throw std::bad_alloc();
    T *p = static_cast<T *>(std::calloc(count, sizeof(T)));
    if (!p)
        throw std::bad_alloc();
    return p;
}

void fill(const tinyobj::ObjReader &reader, ps_obj_mesh *out)
{
    const tinyobj::attrib_t &attrib = reader.GetAttrib();
    out->position_count = attrib.vertices.size() / 3;
    out->positions = alloc_array<double>(out->position_count * 3);
    for (size_t i = 0; i < out->position_count * 3; i++)
        out->positions[i] = attrib.vertices[i];
    out->normal_count = attrib.normals.size() / 3;
    out->normals = alloc_array<double>(out->normal_count * 3);
    for (size_t i = 0; i < out->normal_count * 3; i++)
        out->normals[i] = attrib.normals[i];

    out->texcoord_count = attrib.texcoords.size() / 2;
    out->texcoords = alloc_array<double>(out->texcoord_count * 2);
    for (size_t i = 0; i < out->texcoord_count * 2; i++)
        out->texcoords[i] = attrib.texcoords[i];

    size_t tris = 0;
    for (const tinyobj::shape_t &shape : reader.GetShapes())
        for (unsigned char nv : shape.mesh.num_face_vertices)
            if (nv >= 3)
                tris += nv - 2u;
    out->tri_v = alloc_array<int32_t>(tris * 3);
    out->tri_n = alloc_array<int32_t>(tris * 3);
    out->tri_t = alloc_array<int32_t>(tris * 3);
    out->tri_mat = alloc_array<int32_t>(tris);
    size_t t = 0;
    for (const tinyobj::shape_t &shape : reader.GetShapes()) {
        size_t base = 0;
        for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); f++) {
            size_t nv = shape.mesh.num_face_vertices[f];
            int mat = f < shape.mesh.material_ids.size() ? shape.mesh.material_ids[f] : -1;
            for (size_t k = 1; nv >= 3 && k + 1 < nv; k++, t++) {
                const tinyobj::index_t idx[3] = {shape.mesh.indices[base], shape.mesh.indices[base + k],
                                                 shape.mesh.indices[base + k + 1]};
                for (int c = 0; c < 3; c++) {
                    out->tri_v[t * 3 + c] = idx[c].vertex_index;
                    out->tri_n[t * 3 + c] = idx[c].normal_index;
                    out->tri_t[t * 3 + c] = idx[c].texcoord_index;
                }
                out->tri_mat[t] = mat;
            }
            base += nv;
        }
    }
    out->triangle_count = t;

    const std::vector<tinyobj::material_t> &mats = reader.GetMaterials();
    out->material_count = mats.size();
    out->materials = alloc_array<ps_obj_material>(mats.size());
    for (size_t i = 0; i < mats.size(); i++) {
        ps_obj_material &m = out->materials[i];
        std::snprintf(m.name, sizeof m.name, "%s", mats[i].name.c_str());
        for (int c = 0; c < 3; c++) {
            m.kd[c] = mats[i].diffuse[c];
            m.ks[c] = mats[i].specular[c];
            m.ke[c] = mats[i].emission[c];
        }
        m.ns = mats[i].shininess;
        m.ni = mats[i].ior;
        m.illum = mats[i].illum;
        std::snprintf(m.map_kd, sizeof m.map_kd, "%s", mats[i].diffuse_texname.c_str());
    }
}

} // namespace

extern "C" int ps_tinyobj_parse(const char *obj_text, size_t obj_len, const char *mtl_text, size_t mtl_len,
                                ps_obj_mesh *out, char *msg, size_t msg_size)
{
    std::memset(out, 0, sizeof *out);
    try {
        tinyobj::ObjReaderConfig config;
        // We triangulate ourselves (fans), so that every polygon is kept and the
        // face order stays the file's order.
        config.triangulate = false;
        config.vertex_color = false;
        tinyobj::ObjReader reader;
        if (!reader.ParseFromString(std::string(obj_text, obj_len), std::string(mtl_text, mtl_len), config)) {
            set_msg(msg, msg_size, reader.Error().empty() ? std::string("cannot parse") : reader.Error());
            return 1;
        }
        fill(reader, out);
        return 0;
    } catch (const std::bad_alloc &) {
        set_msg(msg, msg_size, "out of memory");
    } catch (const std::exception &e) {
        set_msg(msg, msg_size, e.what());
    } catch (...) {
        set_msg(msg, msg_size, "unexpected failure in tinyobjloader");
    }
    ps_obj_free(out);
    return 1;
}
