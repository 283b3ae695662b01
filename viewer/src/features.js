// What a click hit: the lot and the symbol of an instance or of a polygon, from the tile's property tables.
//
// 3d-tiles-renderer reads EXT_mesh_features (per vertex) and EXT_structural_metadata; instances carry their
// feature IDs in EXT_instance_features, which three's GLTFLoader does not read: it puts the extra
// instancing attributes on the mesh's geometry, which the tile's nodes of one asset share. So this loader
// plugin keeps each instanced mesh's own feature ID accessors in its userData.
import { Vector3 } from "three";

export class InstanceFeatures {
  constructor(parser) {
    this.parser = parser;
    this.name = "EXT_instance_features";
  }

  async afterRoot() {
    const { json } = this.parser;
    await Promise.all((json.nodes ?? []).map(async (definition, index) => {
      const features = definition.extensions?.EXT_instance_features;
      const instancing = definition.extensions?.EXT_mesh_gpu_instancing;
      if (!features || !instancing) return;
      const node = await this.parser.getDependency("node", index);
      const ids = await Promise.all(features.featureIds.map(
        (set) => this.parser.getDependency("accessor", instancing.attributes[`_FEATURE_ID_${set.attribute}`])));
      node.traverse((object) => {
        if (object.isInstancedMesh) {
          object.userData.instanceFeatures = features.featureIds.map((set, k) => ({ ...set, ids: ids[k] }));
        }
      });
    }));
  }
}

function structuralMetadata(object) {
  for (let o = object; o; o = o.parent) if (o.userData.structuralMetadata) return o.userData.structuralMetadata;
  return null;
}

// {label: {property: value}} of the features under a raycast hit, or null where it hit none.
export function pickedFeatures(hit) {
  const metadata = structuralMetadata(hit.object);
  if (!metadata) return null;
  let sets = [];
  if (hit.object.isInstancedMesh && hit.object.userData.instanceFeatures) {
    sets = hit.object.userData.instanceFeatures.map((set) => ({ ...set, id: set.ids.getX(hit.instanceId) }));
  } else if (hit.object.userData.meshFeatures) {
    const features = hit.object.userData.meshFeatures;
    const ids = features.getFeatures(hit.faceIndex, hit.barycoord ?? new Vector3(1, 0, 0));
    sets = features.getFeatureInfo().map((set, k) => ({ ...set, id: ids[k] }));
  }
  const picked = {};
  for (const set of sets) {
    if (set.propertyTable === undefined || set.id === null || set.id < 0 || set.id >= set.featureCount) continue;
    picked[set.label ?? `table ${set.propertyTable}`] = metadata.getPropertyTableData(set.propertyTable, set.id);
  }
  return Object.keys(picked).length ? picked : null;
}
