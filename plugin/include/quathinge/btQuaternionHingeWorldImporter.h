/** \file
Loading .bullet files with their quaternion hinges: btQuaternionHingeWorldImporter, btBulletWorldImporter plus the
QuatHinge chunks.

Every hinge written by btQuaternionHingeConstraint::serialize comes back as a btQuaternionHingeConstraint with all its
settings (btQuaternionHingeSerialization.h: the joint's stock chunk plus a QuatHinge chunk); stock hinges stay
btHingeConstraints (btReplaceHingeConstraints converts them if wanted). How: Bullet's importer first builds a stock
btHingeConstraint from each hinge chunk, as a plain Bullet does; then, while the file is still parsed (in
convertAllObjects, which loadFile and loadFileFromMemory call), each hinge chunk that has a QuatHinge chunk is paired
with the stock hinge built from it (same order, same bodies), and that stock hinge is replaced by the quaternion hinge:
in the world (removed, the new joint added with the same disableCollisionsBetweenLinkedBodies choice, at the end of
the world's list), in the importer's list of constraints (getConstraintByIndex: same index) and under its name. The
importer owns the quaternion hinges, as it owns everything it loaded: deleteAllData() removes and deletes them.

A QuatHinge chunk that btQuaternionHingeDeserialize refuses (a corrupt file) leaves its stock hinge in place and is
counted (getNumRefusedQuaternionHinges); the importer never throws: the refusal's message goes to the error callback
(btQuaternionHingeErrors.h) in both builds. Chunk lengths are trusted as Bullet's file loader trusts them. QuatHinge
chunks are found in files of this machine's byte order and pointer size (any precision); in another file the hinges
load as stock hinges.

Header-only: it needs Bullet's world importer and file loader (BulletWorldImporter, BulletFileLoader; Debian:
libbullet-extras-dev), which the QuatHinge library itself does not link. Link them where you include this.
*/
#ifndef BT_QUATERNION_HINGE_WORLD_IMPORTER_H
#define BT_QUATERNION_HINGE_WORLD_IMPORTER_H

#include "quathinge/btQuaternionHingeSerialization.h"

#include "BulletFileLoader/bChunk.h"
#include "BulletFileLoader/btBulletFile.h"
#include "BulletWorldImporter/btBulletWorldImporter.h"
#include "btBulletDynamicsCommon.h"

#include <cstring>
#ifndef QUATHINGE_NO_EXCEPTIONS
#include <stdexcept>
#endif

/// Loads .bullet files with their quaternion hinges, in place of btBulletWorldImporter (header-only; link Bullet's
/// world importer and file loader). Stock hinges stay stock; the importer owns what it loaded (deleteAllData()).
/// \code
/// btQuaternionHingeWorldImporter importer(world);  // instead of btBulletWorldImporter
/// if (importer.loadFile("scene.bullet"))           // or loadFileFromMemory(buffer, length)
///   std::printf("%d quaternion hinges\n", importer.getNumQuaternionHinges());
/// importer.deleteAllData();  // removes and deletes what it loaded, quaternion hinges included
/// \endcode
/// More: docs/STABILIZER.md, "Upgrading a world, and files".
class btQuaternionHingeWorldImporter : public btBulletWorldImporter
{
public:
	/// Loads into `world` (null: builds the objects without adding them to a world), as btBulletWorldImporter.
	explicit btQuaternionHingeWorldImporter(btDynamicsWorld* world = 0) : btBulletWorldImporter(world) {}

	/// Hinges restored as quaternion hinges by the last load.
	int getNumQuaternionHinges() const { return m_numQuaternionHinges; }
	/// QuatHinge chunks of the last load that were refused (their stock hinges stayed).
	int getNumRefusedQuaternionHinges() const { return m_numRefused; }

	/// Bullet's conversion, then the swap described above (the file is still parsed here).
	virtual bool convertAllObjects(bParse::btBulletFile* file)
	{
		m_numQuaternionHinges = 0;
		m_numRefused = 0;
		const int first = m_allocatedConstraints.size();
		const bool converted = btBulletWorldImporter::convertAllObjects(file);
		if (converted && !(file->getFlags() & bParse::FD_ENDIAN_SWAP)) restoreQuaternionHinges(*file, first);
		return converted;
	}

private:
	// The chunk's length, from the chunk header just before its data (as Bullet's file loader lays chunks out).
	static size_t chunkLength(const bParse::btBulletFile& file, const char* data)
	{
		int length = 0;
		if (file.getFlags() & bParse::FD_FILE_64)
			std::memcpy(&length, data - sizeof(bParse::bChunkPtr8) + sizeof(int), sizeof(int));
		else
			std::memcpy(&length, data - sizeof(bParse::bChunkPtr4) + sizeof(int), sizeof(int));
		return length > 0 ? size_t(length) : 0;
	}

	void restoreQuaternionHinges(bParse::btBulletFile& file, int first)
	{
		// the stock hinges this load built, in the order Bullet built them (the file's order)
		btAlignedObjectArray<int> built;
		for (int i = first; i < m_allocatedConstraints.size(); ++i)
			if (m_allocatedConstraints[i]->getConstraintType() == HINGE_CONSTRAINT_TYPE) built.push_back(i);
		// the hinge chunks Bullet converted (it skips a constraint none of whose bodies it loaded)
		btAlignedObjectArray<btTypedConstraintData2*> chunks;
		for (int i = 0; i < file.m_constraints.size(); ++i)
		{
			btTypedConstraintData2* data = reinterpret_cast<btTypedConstraintData2*>(file.m_constraints[i]);
			if (data->m_objectType == HINGE_CONSTRAINT_TYPE && (m_bodyMap.find(data->m_rbA) || m_bodyMap.find(data->m_rbB)))
				chunks.push_back(data);
		}
		if (chunks.size() != built.size()) return;  // not the pairing expected: keep Bullet's result as it is
		// old pointer of each parsed block (the loader maps old pointers to blocks)
		btHashMap<btHashPtr, void*> oldPointerOf;
		bParse::bPtrMap& pointers = file.getLibPointers();
		for (int i = 0; i < pointers.size(); ++i)
			if (pointers.getAtIndex(i)) oldPointerOf.insert(*pointers.getAtIndex(i), const_cast<void*>(pointers.getKeyAtIndex(i).getPointer()));
		for (int k = 0; k < chunks.size(); ++k)
		{
			void** oldPointer = oldPointerOf.find(chunks[k]);
			if (!oldPointer) continue;
			const char* quat = static_cast<const char*>(file.findLibPointer(btQuaternionHingeChunkKey(*oldPointer)));
			if (!quat) continue;  // a stock hinge
			// a QuatHinge chunk has no DNA struct, so the loader leaves it in the file's buffer, right after its chunk
			// header; a block the loader allocated (a struct chunk that happens to carry this old pointer) is not one
			bool allocatedByLoader = false;
			for (int b = 0; b < file.m_dataBlocks.size() && !allocatedByLoader; ++b)
				allocatedByLoader = file.m_dataBlocks[b] == quat;
			if (allocatedByLoader) continue;
			btHingeConstraint* stock = static_cast<btHingeConstraint*>(m_allocatedConstraints[built[k]]);
			btQuaternionHingeConstraint* joint = deserialize(quat, chunkLength(file, quat), *stock);
			if (!joint)
			{
				++m_numRefused;
				continue;
			}
			replace(built[k], stock, joint);
			++m_numQuaternionHinges;
		}
	}

	static btQuaternionHingeConstraint* deserialize(const char* data, size_t size, btHingeConstraint& stock)
	{
#ifndef QUATHINGE_NO_EXCEPTIONS
		try
		{
			return btQuaternionHingeDeserialize(data, size, stock.getRigidBodyA(), stock.getRigidBodyB());
		}
		catch (const std::invalid_argument& refusal)
		{
			btQuaternionHingeReportError(refusal.what());
			return 0;
		}
#else
		return btQuaternionHingeDeserialize(data, size, stock.getRigidBodyA(), stock.getRigidBodyB());  // null: refused
#endif
	}

	void replace(int index, btHingeConstraint* stock, btQuaternionHingeConstraint* joint)
	{
		if (m_dynamicsWorld) btSwapConstraintInWorld(m_dynamicsWorld, stock, joint);
		if (const char* const* name = m_objectNameMap.find(stock))
		{
			const char* kept = *name;
			m_objectNameMap.remove(stock);
			m_objectNameMap.insert(joint, kept);
			m_nameConstraintMap.insert(kept, joint);
		}
		m_allocatedConstraints[index] = joint;
		delete stock;  // built by this importer, which owns it
	}

	int m_numQuaternionHinges = 0;
	int m_numRefused = 0;
};

/// btReplaceHingeConstraints (quathinge/btQuaternionHingeConstraint.h) on a world that `importer` loaded, wholly or in
/// part: every stock hinge in the world is replaced; *removedYours (if not null) gets only the stock hinges taken out
/// that the importer does not own (those your app added), for you to delete. The importer's stay its own: its
/// deleteAllData() deletes them, once. The replacements in *added are yours (remove and delete them before
/// deleteAllData() deletes the bodies).
///
///     btBulletWorldImporter importer(world);
///     importer.loadFile("scene.bullet");
///     btAlignedObjectArray<btQuaternionHingeConstraint*> added;
///     btAlignedObjectArray<btHingeConstraint*> removed;
///     btReplaceHingeConstraints(world, &added, &removed, importer);  // removed: none of the importer's
inline int btReplaceHingeConstraints(btDynamicsWorld* world, btAlignedObjectArray<btQuaternionHingeConstraint*>* added,
									 btAlignedObjectArray<btHingeConstraint*>* removedYours,
									 const btWorldImporter& importer)
{
	btAlignedObjectArray<btTypedConstraint*> owned;
	owned.reserve(importer.getNumConstraints());
	for (int i = 0; i < importer.getNumConstraints(); ++i) owned.push_back(importer.getConstraintByIndex(i));
	return btReplaceHingeConstraints(world, added, removedYours, &owned);
}

#endif  // BT_QUATERNION_HINGE_WORLD_IMPORTER_H
