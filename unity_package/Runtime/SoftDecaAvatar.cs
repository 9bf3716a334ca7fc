using System;
using System.Collections.Generic;
using System.IO;
using System.Threading.Tasks;
using SoftDeca;
using Unity.Collections;
using UnityEngine;

namespace SoftDeca.Unity
{
    /// <summary>A material parameter set on the whole face.</summary>
    [Serializable]
    public struct ParameterSetting
    {
        public string name;
        public float value;
    }

    /// <summary>A material parameter changed inside a sphere on the face (a region control).</summary>
    [Serializable]
    public struct MaterialRegion
    {
        public string parameter;
        [Tooltip("Centre in the mesh's local space (metres)")] public Vector3 centre;
        [Min(0)] public float radius;
        public float value;
    }

    /// <summary>
    /// Drives a mesh in the template topology with SoftDECA (from blendshape weights), SparseSoftDECA
    /// (from a tracked face mesh) or linear blendshapes. The mesh comes from a MeshFilter or a
    /// SkinnedMeshRenderer on this object; its blendshapes named after ARKit's 52 give the
    /// avatar's expressions. Each frame writes positions and normals through NativeArrays:
    /// nothing is allocated on the managed heap per frame.
    /// </summary>
    [AddComponentMenu("SoftDECA/SoftDECA Avatar")]
    [DisallowMultipleComponent]
    public sealed class SoftDecaAvatar : MonoBehaviour
    {
        public enum Method { SoftDeca, Sparse, Linear }

        [Tooltip("Model bundle folder or .tar, relative to StreamingAssets (or absolute)")]
        public string bundlePath = "softdeca-default";
        [Tooltip("Optional: the template-topology neutral OBJ (saved as .bytes) when Unity's import split or reordered vertices")]
        public TextAsset templateObj;
        public SoftDecaFaceInput input;
        public Method method = Method.SoftDeca;
        public bool dynamics;
        public Precision precision = Precision.Half;
        [Range(1, 8)] public int threads = 1;
        public List<ParameterSetting> parameters = new List<ParameterSetting>();
        public List<MaterialRegion> regions = new List<MaterialRegion>();

        private Model model;
        private Avatar avatar;
        private LandmarkInput landmarks;
        private Mesh mesh;
        private int[] toTemplate;           // Unity vertex -> template vertex
        private float[] weights = new float[BlendshapeMap.Count];
        private float[] libraryNeutral;     // template order, library frame
        private int[] skinTriangles;
        private NativeArray<Vector3> positions, normals;
        private bool dirty;
        // The running prepare: material changes are prepared off the main thread (the physics
        // at prepare takes a second or more) while frames keep the last preparation.
        private Task preparing;
        private bool prepared;

        public Avatar Native { get { return avatar; } }
        /// <summary>Whether a material change is still being prepared (frames show the previous one).</summary>
        public bool Preparing { get { return preparing != null && !preparing.IsCompleted; } }
        public Model Model { get { return model; } }

        private void OnEnable()
        {
            Mesh source = SourceMesh();
            if (source == null) throw new InvalidOperationException("SoftDecaAvatar needs a MeshFilter or SkinnedMeshRenderer with a mesh");
            string path = Path.IsPathRooted(bundlePath) ? bundlePath : Path.Combine(Application.streamingAssetsPath, bundlePath);
            model = Model.Load(path);
            mesh = Instantiate(source);
            mesh.MarkDynamic();
            AssignMesh(mesh);
            BuildAvatar(source);
            positions = new NativeArray<Vector3>(mesh.vertexCount, Allocator.Persistent);
            normals = new NativeArray<Vector3>(mesh.vertexCount, Allocator.Persistent);
            if (model.Info.HasSparse != 0) landmarks = new LandmarkInput(model);
            prepared = false;
            ApplyMaterial();
        }

        private void OnDisable()
        {
            FinishPrepare(true);
            if (avatar != null) avatar.Dispose();
            if (model != null) model.Dispose();
            avatar = null;
            model = null;
            if (positions.IsCreated) positions.Dispose();
            if (normals.IsCreated) normals.Dispose();
        }

        /// <summary>Re-applies parameters and regions at the next frame (the inspector calls this).</summary>
        public void MarkMaterialDirty() { dirty = true; }

        private Mesh SourceMesh()
        {
            var skinned = GetComponent<SkinnedMeshRenderer>();
            if (skinned != null) return skinned.sharedMesh;
            var filter = GetComponent<MeshFilter>();
            return filter != null ? filter.sharedMesh : null;
        }

        private void AssignMesh(Mesh m)
        {
            var skinned = GetComponent<SkinnedMeshRenderer>();
            if (skinned != null)
            {
                skinned.sharedMesh = m;
                for (int i = 0; i < m.blendShapeCount; ++i) skinned.SetBlendShapeWeight(i, 0);  // the avatar applies them
            }
            else GetComponent<MeshFilter>().sharedMesh = m;
        }

        private void BuildAvatar(Mesh source)
        {
            int headCount = (int)model.Info.HeadVertexCount;
            Vector3[] unity = source.vertices;
            float[] unityLibrary = new float[unity.Length * 3];
            for (int i = 0; i < unity.Length; ++i)
            {
                unityLibrary[3 * i] = -unity[i].x;  // Unity's importer negated x
                unityLibrary[3 * i + 1] = unity[i].y;
                unityLibrary[3 * i + 2] = unity[i].z;
            }
            int[] templateTriangles;
            if (templateObj != null)
            {
                ObjText obj = ObjText.Parse(templateObj.text);
                libraryNeutral = obj.Positions;
                templateTriangles = obj.Triangles;
                toTemplate = TemplateMapping.Build(unityLibrary, libraryNeutral);
            }
            else
            {
                if (unity.Length != headCount)
                    throw new InvalidOperationException("the mesh has " + unity.Length + " vertices, the bundle's template " + headCount +
                                                        ": assign templateObj (the neutral OBJ) so vertices can be matched");
                libraryNeutral = unityLibrary;
                templateTriangles = MeshConversion.TrianglesToLibrary(source.triangles);
                toTemplate = new int[headCount];
                for (int i = 0; i < headCount; ++i) toTemplate[i] = i;
            }
            avatar = new Avatar(model, libraryNeutral, templateTriangles, Blendshapes(source, headCount), (uint)threads, precision);
            skinTriangles = model.SkinTriangles();
            avatar.SetDynamics(dynamics);
        }

        // The mesh's blendshapes named after ARKit's shapes, as template-order deltas; null without any.
        private float[] Blendshapes(Mesh source, int headCount)
        {
            var names = new string[source.blendShapeCount];
            for (int i = 0; i < names.Length; ++i) names[i] = source.GetBlendShapeName(i);
            var map = new BlendshapeMap(names);
            if (map.Unmatched.Length == names.Length) return null;
            var deltas = new float[BlendshapeMap.Count * headCount * 3];
            var frame = new Vector3[source.vertexCount];
            for (int i = 0; i < names.Length; ++i)
            {
                int c = map.ToCanonical(i);
                if (c < 0) continue;
                source.GetBlendShapeFrameVertices(i, source.GetBlendShapeFrameCount(i) - 1, frame, null, null);
                for (int v = 0; v < frame.Length; ++v)
                {
                    int t = 3 * (c * headCount + toTemplate[v]);
                    deltas[t] = -frame[v].x;
                    deltas[t + 1] = frame[v].y;
                    deltas[t + 2] = frame[v].z;
                }
            }
            return deltas;
        }

        private void ApplyMaterial()
        {
            avatar.ResetParameters();
            foreach (var p in parameters) avatar.SetParameter(p.name, p.value);
            var byParameter = new Dictionary<string, float[]>();
            foreach (var r in regions)
            {
                float[] faces;
                if (!byParameter.TryGetValue(r.parameter, out faces))
                {
                    faces = new float[skinTriangles.Length / 3];
                    float baseline = (float)avatar.GetParameter(r.parameter);
                    for (int f = 0; f < faces.Length; ++f) faces[f] = baseline;
                    byParameter[r.parameter] = faces;
                }
                RegionMap.Paint(libraryNeutral, skinTriangles, faces, -r.centre.x, r.centre.y, r.centre.z, r.radius, r.value);
            }
            foreach (var kv in byParameter) avatar.SetParameterFaces(kv.Key, kv.Value);
            dirty = false;
#if UNITY_WEBGL && !UNITY_EDITOR
            avatar.Prepare();  // no threads
            prepared = true;
#else
            Avatar target = avatar;
            preparing = Task.Run(() => target.Prepare());
#endif
        }

        // Collects a finished prepare (wait: block until it finishes); a failed one is logged and
        // the avatar keeps its previous preparation.
        private void FinishPrepare(bool wait)
        {
            if (preparing == null || (!wait && !preparing.IsCompleted)) return;
            try
            {
                preparing.Wait();
                prepared = true;
            }
            catch (AggregateException e)
            {
                Debug.LogException(e.InnerException ?? e, this);
            }
            preparing = null;
        }

        private void Update()
        {
            if (avatar == null || input == null) return;
            FinishPrepare(false);
            if (dirty && preparing == null) ApplyMaterial();
            if (!prepared) return;  // the first preparation is still running
            if (method == Method.Sparse && landmarks != null && input.TryGetLandmarks(landmarks))
                avatar.EvaluateLandmarks(landmarks.Points);
            else if (input.TryGetWeights(weights))
            {
                if (method == Method.Linear) avatar.EvaluateLinear(weights);
                else avatar.EvaluateWeights(weights);
            }
            else return;
            WriteMesh();
        }

        private void WriteMesh()
        {
            float[] v = avatar.Vertices, n = avatar.Normals;
            for (int i = 0; i < toTemplate.Length; ++i)
            {
                int t = 3 * toTemplate[i];
                positions[i] = new Vector3(-v[t], v[t + 1], v[t + 2]);
                normals[i] = new Vector3(-n[t], n[t + 1], n[t + 2]);
            }
            mesh.SetVertices(positions);
            mesh.SetNormals(normals);
            mesh.RecalculateBounds();
        }
    }
}
