/* productions of plant.l */
A --> F@Gc(2)
