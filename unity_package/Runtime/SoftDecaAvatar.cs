using System;
using System.Collections.Generic;
using System.IO;
using System.Threading.Tasks;
using SoftDeca;
using Unity.Collections;
using Unity.Collections.LowLevel.Unsafe;
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
        [Tooltip("Centre in the mesh's local space (its unit: metres for the template)")] public Vector3 centre;
        [Min(0)] public float radius;
        public float value;
    }

    /// <summary>
    /// Drives the mesh of a MeshFilter or SkinnedMeshRenderer on this object with SoftDECA (from
    /// blendshape weights), SparseSoftDECA (from a tracked face mesh) or linear blendshapes. With
    /// a fit (the inspector's Fit button writes one) the mesh is the user's own avatar, of any
    /// topology, a head or a whole body; without, it is a head in the bundle's template topology.
    /// Its blendshapes named after ARKit's 52 give the avatar's expressions. The corrected
    /// vertices are written into the mesh the renderer draws, so a SkinnedMeshRenderer's bones
    /// still skin them. Each frame writes positions and normals through NativeArrays: nothing is
    /// allocated on the managed heap per frame. Components naming the same bundle share its
    /// loaded Model, and their SoftDECA frames run in one batch call per frame (AvatarBatch: the
    /// model's per-frame networks run once for all of them) in the frame's first LateUpdate.
    /// </summary>
    [AddComponentMenu("SoftDECA/SoftDECA Avatar")]
    [DisallowMultipleComponent]
    public sealed class SoftDecaAvatar : MonoBehaviour
    {
        public enum Method { SoftDeca, Sparse, Linear }

        [Tooltip("Model bundle folder or .tar, relative to StreamingAssets (or absolute)")]
        public string bundlePath = "softdeca-default";
        [Tooltip("The fit of this mesh to the bundle's template (the Fit button below writes it): animates your own avatar. Empty: the mesh is in the template topology")]
        public TextAsset fit;
        [Tooltip("Optional, template topology only: the template-topology neutral OBJ (saved as .bytes) when Unity's import split or reordered vertices")]
        public TextAsset templateObj;
        public SoftDecaFaceInput input;
        public Method method = Method.SoftDeca;
        public bool dynamics;
        [Tooltip("How SoftDECA stores its tables (hyper-tensor, vertex and residual stages). Default: the library's choice for this model, within its accuracy bound")]
        public Precision precision = Precision.Default;
        [Tooltip("How SparseSoftDECA stores its hyper-tensor. Default: the library's choice for this model, within its accuracy bound")]
        public Precision sparsePrecision = Precision.Default;
        [Range(1, 8)] public int threads = 1;
        public List<ParameterSetting> parameters = new List<ParameterSetting>();
        public List<MaterialRegion> regions = new List<MaterialRegion>();

        private SharedModel sharedModel;    // the bundle's Model, shared with the other components naming it
        private Model model;
        private Avatar avatar;
        private AvatarFit avatarFit;
        private LandmarkInput landmarks;
        private Mesh sourceMesh;            // the renderer's own mesh, given back on disable
        private Mesh mesh;                  // the copy the avatar writes
        private int[] toAvatar;             // Unity vertex -> avatar vertex (template or fitted)
        private float[] weights = new float[BlendshapeMap.Count];
        private float[] libraryNeutral;     // the avatar's neutral (avatar order, library frame)
        private int[] mapTriangles;         // the triangles material maps are given over
        private NativeArray<Vector3> positions, normals;
        private bool dirty;
        // The running prepare: material changes are prepared off the main thread (the physics
        // at prepare takes a second or more) while frames keep the last preparation.
        private Task preparing;
        private bool prepared;

        public Avatar Native { get { return avatar; } }
        /// <summary>Whether a material change is still being prepared (frames show the previous one).</summary>
        public bool Preparing { get { return preparing != null && !preparing.IsCompleted; } }
        /// <summary>The bundle's loaded Model, shared by every enabled component naming the same bundle: not to be disposed.</summary>
        public Model Model { get { return model; } }
        internal float[] FrameWeights { get { return weights; } }

        /// <summary>The bundle's path: bundlePath under StreamingAssets, or as it is when absolute.</summary>
        public string BundleFullPath
        {
            get { return Path.IsPathRooted(bundlePath) ? bundlePath : Path.Combine(Application.streamingAssetsPath, bundlePath); }
        }

        /// <summary>The renderer's own mesh (what a fit is made for), also while the avatar draws its copy.</summary>
        public Mesh SourceMesh
        {
            get
            {
                if (sourceMesh != null) return sourceMesh;
                var skinned = GetComponent<SkinnedMeshRenderer>();
                if (skinned != null) return skinned.sharedMesh;
                var filter = GetComponent<MeshFilter>();
                return filter != null ? filter.sharedMesh : null;
            }
        }

        private void OnEnable()
        {
            Mesh source = SourceMesh;
            if (source == null) throw new InvalidOperationException("SoftDecaAvatar needs a MeshFilter or SkinnedMeshRenderer with a mesh");
            sharedModel = SharedModel.Acquire(BundleFullPath);
            model = sharedModel.Model;
            if (fit != null) BuildFitted(source);
            else BuildTemplate(source);
            avatar.SetDynamics(dynamics);
            sourceMesh = source;
            mesh = Instantiate(source);
            mesh.MarkDynamic();
            AssignMesh(mesh, true);
            positions = new NativeArray<Vector3>(mesh.vertexCount, Allocator.Persistent);
            normals = new NativeArray<Vector3>(mesh.vertexCount, Allocator.Persistent);
            if (model.Info.HasSparse != 0) landmarks = new LandmarkInput(model);
            prepared = false;
            ApplyMaterial();
        }

        private void OnDisable()
        {
            BatchedFrames.Withdraw(this);
            FinishPrepare(true);
            if (avatar != null) avatar.Dispose();
            if (avatarFit != null) avatarFit.Dispose();
            if (sharedModel != null) sharedModel.Release();
            avatar = null;
            avatarFit = null;
            sharedModel = null;
            model = null;
            if (sourceMesh != null) AssignMesh(sourceMesh, false);
            if (mesh != null) Destroy(mesh);
            sourceMesh = null;
            mesh = null;
            if (positions.IsCreated) positions.Dispose();
            if (normals.IsCreated) normals.Dispose();
        }

        /// <summary>Re-applies parameters and regions at the next frame (the inspector calls this).</summary>
        public void MarkMaterialDirty() { dirty = true; }

        private void AssignMesh(Mesh m, bool avatarApplies)
        {
            var skinned = GetComponent<SkinnedMeshRenderer>();
            if (skinned != null)
            {
                skinned.sharedMesh = m;
                if (avatarApplies)
                    for (int i = 0; i < m.blendShapeCount; ++i) skinned.SetBlendShapeWeight(i, 0);  // the avatar applies them
            }
            else GetComponent<MeshFilter>().sharedMesh = m;
        }

        /// <summary>
        /// A Unity mesh as the fit and the fitted avatar take it: positions and shapes in the
        /// library's frame, its ARKit shapes by name, split vertices welded (AvatarMesh.FromUnity).
        /// The Fit button and the avatar at run time read the mesh through this one function.
        /// </summary>
        public static AvatarMesh ReadAvatarMesh(Mesh source) { return ReadMesh(source, null, 0); }

        // The mesh's positions, triangles and ARKit shapes: onto target vertices by toTarget, or welded.
        private static unsafe AvatarMesh ReadMesh(Mesh source, int[] toTarget, int targetVertexCount)
        {
            var names = new string[source.blendShapeCount];
            for (int i = 0; i < names.Length; ++i) names[i] = source.GetBlendShapeName(i);
            var frame = new Vector3[source.vertexCount];
            ShapeReader read = (shape, deltas) =>
            {
                source.GetBlendShapeFrameVertices(shape, source.GetBlendShapeFrameCount(shape) - 1, frame, null, null);
                Flatten(frame, deltas);
            };
            Vector3[] vertices = source.vertices;
            var unity = new float[3 * vertices.Length];
            Flatten(vertices, unity);
            return toTarget == null ? AvatarMesh.FromUnity(unity, source.triangles, names, read)
                                    : AvatarMesh.FromUnity(unity, source.triangles, names, read, toTarget, targetVertexCount);
        }

        private static unsafe void Flatten(Vector3[] v, float[] xyz)
        {
            fixed (Vector3* p = v)
            {
                float* f = (float*)p;
                for (int i = 0; i < xyz.Length; ++i) xyz[i] = f[i];
            }
        }

        // The user's own avatar: the saved fit and the mesh it was made for.
        private void BuildFitted(Mesh source)
        {
            AvatarMesh own = ReadAvatarMesh(source);
            avatarFit = AvatarFit.LoadBytes(model, fit.bytes, Application.temporaryCachePath);
            avatar = new Avatar(model, avatarFit, own, (uint)threads, precision, sparsePrecision);
            toAvatar = own.UnityToAvatar;
            libraryNeutral = own.Neutral;
            mapTriangles = own.Triangles;
        }

        // A head in the template topology, its Unity vertices matched to the template's.
        private void BuildTemplate(Mesh source)
        {
            int headCount = (int)model.Info.HeadVertexCount;
            int[] templateTriangles = null;
            if (templateObj != null)
            {
                ObjText obj = ObjText.Parse(templateObj.text);
                libraryNeutral = obj.Positions;
                templateTriangles = obj.Triangles;
                Vector3[] unity = source.vertices;
                var unityLibrary = new float[unity.Length * 3];
                Flatten(unity, unityLibrary);
                MeshConversion.PositionsToLibrary(unityLibrary, unityLibrary);
                toAvatar = TemplateMapping.Build(unityLibrary, libraryNeutral);
            }
            else
            {
                if (source.vertexCount != headCount)
                    throw new InvalidOperationException("the mesh has " + source.vertexCount + " vertices, the bundle's template " +
                                                        headCount + ": assign a fit (the Fit button) for a mesh of its own " +
                                                        "topology, or templateObj (the neutral OBJ) so vertices can be matched");
                toAvatar = new int[headCount];
                for (int i = 0; i < headCount; ++i) toAvatar[i] = i;
            }
            AvatarMesh rig = ReadMesh(source, toAvatar, headCount);
            if (templateObj == null)
            {
                libraryNeutral = rig.Neutral;
                templateTriangles = rig.Triangles;
            }
            avatar = new Avatar(model, libraryNeutral, templateTriangles, rig.ShapesFound == 0 ? null : rig.Blendshapes, (uint)threads,
                                precision, sparsePrecision);
            mapTriangles = model.SkinTriangles();
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
                    faces = new float[mapTriangles.Length / 3];
                    float baseline = (float)avatar.GetParameter(r.parameter);
                    for (int f = 0; f < faces.Length; ++f) faces[f] = baseline;
                    byParameter[r.parameter] = faces;
                }
                var centre = new[] { r.centre.x, r.centre.y, r.centre.z };
                MeshConversion.PositionsToLibrary(centre, centre);
                RegionMap.Paint(libraryNeutral, mapTriangles, faces, centre[0], centre[1], centre[2], r.radius, r.value);
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
                if (method != Method.Linear)
                {
                    BatchedFrames.Defer(this);  // SoftDECA: with the bundle's other avatars, in LateUpdate
                    return;
                }
                avatar.EvaluateLinear(weights);
            }
            else return;
            WriteMesh();
        }

        private void LateUpdate() { BatchedFrames.EvaluateOnce(Time.frameCount); }

        // A deferred SoftDECA frame's outcome: the mesh written, or (error) logged and the mesh
        // left at its last frame.
        internal void FinishFrame(SoftDecaException error)
        {
            if (avatar == null) return;  // disabled meanwhile
            if (error != null) Debug.LogException(error, this);
            else WriteMesh();
        }

        private unsafe void WriteMesh()
        {
            MeshConversion.PositionsToUnity(avatar.Vertices, toAvatar, (float*)NativeArrayUnsafeUtility.GetUnsafePtr(positions),
                                            positions.Length);
            MeshConversion.PositionsToUnity(avatar.Normals, toAvatar, (float*)NativeArrayUnsafeUtility.GetUnsafePtr(normals),
                                            normals.Length);
            mesh.SetVertices(positions);
            mesh.SetNormals(normals);
            mesh.RecalculateBounds();
        }
    }
}
